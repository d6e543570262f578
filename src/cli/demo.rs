//! `dressform demo`: the pipeline on a built-in synthetic customer.

use super::Failure;

#[derive(Debug, clap::Args)]
pub struct DemoArgs {}

pub fn run(_args: &DemoArgs) -> Result<(), Failure> {
    Err(Failure::other("the demo is being built"))
}
