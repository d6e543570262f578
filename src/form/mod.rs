//! The robotic dress form: its rings fitted to the mannequin, the set-points that result, the
//! one safety rule every target passes, and the host controller that drives the form.

pub mod controller;
pub mod form_fit;
pub mod safety;
pub mod setpoints;
