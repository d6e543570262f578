//! `dressform reset [--form <form.toml>] (--serial <path> | --slcan <path> | --can <iface> |
//! --sim)`: clear every latched fault whose cause is gone (FaultReset to every node in Fault),
//! saying in words what each node held and what remains. Exit status 1 if a fault remains.

use super::Failure;
use super::link::{self, FormArg, LinkArgs, runtime};
use dressform::controller::faults::describe;
use dressform::controller::simulated::SimConfig;
use dressform::controller::{LinkSpec, ResetReport, reset};

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
        match args.link.spec() {
            LinkSpec::Sim => {
                let rig = link::simulated(&form, &SimConfig::default())?;
                let transport = rig.attach();
                let _armed = link::arm(&transport);
                reset(transport, &form).await.map_err(Failure::other)
            }
            spec => {
                let owned = link::own(&spec)?;
                reset(owned.connection, &form).await.map_err(Failure::other)
            }
        }
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
