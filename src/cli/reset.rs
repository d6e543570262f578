//! `dressform reset [--form <form.toml>] (--serial <path> | --slcan <path> | --can <iface> |
//! --sim)`: clear every latched fault whose cause is gone (FaultReset to every node in Fault),
//! saying in words what each node held and what remains. Exit status 1 if a fault remains.

use super::Failure;
use super::link::{self, FormArg, LinkArgs, runtime};
use dressform::form::controller::faults::describe;
use dressform::form::controller::simulated::SimConfig;
use dressform::form::controller::{ResetReport, reset};

#[derive(Debug, clap::Args)]
pub struct ResetArgs {
    #[command(flatten)]
    form: FormArg,
    #[command(flatten)]
    link: LinkArgs,
}

pub fn run(args: &ResetArgs) -> Result<(), Failure> {
    let form = args.form.load()?;
    let report = runtime()?.block_on(async {
        let owned = link::own(&args.link.spec(), &form, &SimConfig::default())?;
        reset(owned.connection, &form).await.map_err(Failure::other)
    })?;
    print(&report)
}

fn print(report: &ResetReport) -> Result<(), Failure> {
    for problem in &report.problems {
        outln!("problem: {problem}");
    }
    if report.cleared.is_empty() {
        outln!("no node holds a fault");
    }
    let mut remaining = Vec::new();
    for c in &report.cleared {
        if c.remaining.is_empty() {
            outln!("{c}: cleared");
        } else {
            outln!("{c}: NOT cleared, the cause remains: {}", describe(c.remaining));
            remaining.push(c.node.to_string());
        }
    }
    if remaining.is_empty() {
        Ok(())
    } else {
        Err(Failure::other(format!("faults remain on {}", remaining.join(", "))))
    }
}
