//! The integration tests of this crate, as one test binary (each module was its own binary;
//! one binary links the crate once).

#[path = "../../tests/common/skip.rs"]
mod skip;
mod strategies;

mod budget;
mod cantools;
mod dbc;
mod properties;
