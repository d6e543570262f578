//! The robotic dress form: its rings fitted to the mannequin, the set-points that result, the
//! one safety rule every target passes, the host controller that drives the form, and garment
//! fit testing on it.

pub mod controller;
pub mod fit_test;
pub mod form_fit;
pub mod safety;
pub mod setpoints;
