//! `dressform estop (--serial <path> | --slcan <path> | --can <iface> | --sim)`: broadcast an
//! emergency stop. Every node stops at its acceleration limit, powers off and latches
//! `EMERGENCY_STOP` until a FaultReset (the next `dressform drive` sends one, as does
//! `dressform reset`).
//!
//! When a dressform process owns the link (a `drive`, `run`, `status` or `reset` from another
//! terminal), the stop goes through that process's control endpoint and its own thread sends
//! it at once; otherwise this process opens the link and sends it.

use super::Failure;
use super::link::{self, FormArg, LinkArgs, runtime};
use dressform::controller::open::OpenLink;
use dressform::controller::simulated::SimConfig;
use dressform::controller::{Connection, LinkSpec, control, emergency_stop, fault_names};
use std::time::Duration;

#[derive(Debug, clap::Args)]
pub struct EstopArgs {
    #[command(flatten)]
    link: LinkArgs,
    // With --sim: the simulated form's description.
    #[command(flatten)]
    form: FormArg,
}

/// How long the simulated form may take to latch the stop before its nodes are shown
/// (a few ms; more on a busy machine).
const SETTLE: Duration = Duration::from_secs(2);

pub fn run(args: &EstopArgs) -> Result<(), Failure> {
    let spec = args.link.spec();
    if spec == LinkSpec::Sim {
        return on_sim(args);
    }
    if let Some(pid) = control::request_estop(&spec).map_err(Failure::other)? {
        errln!("emergency stop sent by the dressform process {pid}, which owns the link");
        return Ok(());
    }
    let connection = Connection::open(&spec).map_err(|e| {
        Failure::other(format!(
            "{e} (no dressform process owns it; if another program holds the port, stop it \
             there)"
        ))
    })?;
    emergency_stop(&connection).map_err(Failure::other)?;
    errln!("emergency stop sent");
    Ok(())
}

/// A simulated form started for this command (opened as every command opens `--sim`):
/// stopped, then every node shown.
fn on_sim(args: &EstopArgs) -> Result<(), Failure> {
    let form = args.form.load()?;
    let truth = runtime()?.block_on(async {
        let OpenLink { connection, rig } =
            link::open(&LinkSpec::Sim, &form, &SimConfig::default())?;
        let rig = rig.ok_or_else(|| Failure::other("the simulated form did not start"))?;
        emergency_stop(&connection).map_err(Failure::other)?;
        // The host's side closes before the simulated form stops (as `OpenLink` drops them).
        drop(connection);
        let deadline = tokio::time::Instant::now() + SETTLE;
        let latched = || rig.truth().nodes.iter().all(|n| !n.faults.is_empty());
        while !latched() && tokio::time::Instant::now() < deadline {
            tokio::time::sleep(Duration::from_millis(1)).await;
        }
        Ok::<_, Failure>(rig.truth())
    })?;
    outln!("a simulated form started for this command (it ends with it):");
    for node in &truth.nodes {
        outln!("node {}: {}", node.node.get(), fault_names(node.faults).join("|"));
    }
    errln!("emergency stop sent");
    Ok(())
}
