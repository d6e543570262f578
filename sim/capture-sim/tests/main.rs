//! The integration tests of this crate, as one test binary (one binary links the crate once).

mod body_params;
mod capture_artifacts;
mod synthetic_bodies;
