//! The `dressform` command line: a thin layer over the library (see `dressform --help`).

#[cfg(all(target_os = "linux", target_env = "gnu"))]
mod allocator;
mod cli;

use clap::Parser;
use std::process::ExitCode;

#[cfg(all(target_os = "linux", target_env = "gnu"))]
#[global_allocator]
static ALLOCATOR: allocator::Allocator = allocator::Allocator;

fn main() -> ExitCode {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    allocator::configure();
    let args = cli::Args::parse();
    match cli::run(args) {
        Ok(()) if cli::output_failed() => ExitCode::FAILURE,
        Ok(()) => ExitCode::SUCCESS,
        Err(failure) => {
            let message = dressform::messages::bounded(&failure.message);
            cli::write_err(format_args!("error: {message}\n"));
            ExitCode::from(failure.exit_code)
        }
    }
}
