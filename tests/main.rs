//! The integration tests of this crate, as one test binary (each module was its own binary;
//! one binary links the crate once).

mod common;

mod analytic_sections;
mod bad_input;
mod body_model;
mod canonical_frame;
mod controller_cli;
mod controller_estop;
mod controller_liveness;
mod controller_pty;
mod controller_safety;
mod controller_setpoints;
mod controller_sim;
mod controller_socketcan;
mod demo;
mod fitting;
mod formats;
mod fuzz_readers;
mod makehuman;
mod mannequin;
mod mannequin_file;
mod mannequin_quality;
mod measurements;
mod outputs;
mod pose_symmetry;
mod pose_symmetry_cases;
mod pose_symmetry_proportions;
mod preview;
mod run_end_to_end;
mod segmentation;
mod segmentation_makehuman;
mod segmentation_stances;
mod sim_cli;
mod synthetic_bodies;
mod synthetic_mannequin;
