//! The commands that need the simulator (`demo`, `sim`), in a dressform built without it
//! (cargo feature `simulator`): they parse whatever follows them and refuse with one line,
//! exit status 2, rather than being unknown.

use super::Failure;
use super::link::{SIMULATOR, not_built};

/// `dressform demo`.
pub mod demo {
    use super::*;

    /// Whatever was given (nothing is read: the command refuses).
    #[derive(Debug, clap::Args)]
    pub struct DemoArgs {
        #[arg(hide = true, allow_hyphen_values = true, trailing_var_arg = true)]
        _given: Vec<String>,
    }

    /// Refuses: no simulator.
    pub fn run(_: &DemoArgs) -> Result<(), Failure> {
        Err(not_built("dressform demo", SIMULATOR))
    }
}

/// `dressform sim`.
pub mod sim {
    use super::*;

    /// Whatever was given (nothing is read: the command refuses).
    #[derive(Debug, clap::Args)]
    pub struct ServeArgs {
        #[arg(hide = true, allow_hyphen_values = true, trailing_var_arg = true)]
        _given: Vec<String>,
    }

    /// Refuses: no simulator.
    pub fn run(_: &ServeArgs) -> Result<(), Failure> {
        Err(not_built("dressform sim", SIMULATOR))
    }
}
