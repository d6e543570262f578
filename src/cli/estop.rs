//! `dressform estop (--serial <path> | --slcan <path> | --can <iface> | --sim)`: broadcast an
//! emergency stop. Every node stops at its acceleration limit, powers off and latches
//! `EMERGENCY_STOP` until a FaultReset (the next `dressform drive` sends one, as does
//! `dressform reset`).
//!
//! When a dressform process owns the link (a `drive`, `run`, `demo`, `status` or `reset` from
//! another terminal), the stop goes through that process's control endpoint and its own thread
//! sends it at once. Otherwise — no owner, an owner that does not answer or that belongs to
//! another user — this process sends it on the link: opened as usual, or, when another
//! process holds the device, written beside it without a lock (see
//! [`shared_stop_gate`]). A stop is never refused.

use super::Failure;
use super::link::{self, FormArg, LinkArgs};
use dressform::form::controller::transport::shared_stop_gate;
use dressform::form::controller::{Connection, StopCause, control, emergency_stop};

#[derive(Debug, clap::Args)]
pub struct EstopArgs {
    #[command(flatten)]
    link: LinkArgs,
    // With --sim: the simulated form's description.
    #[command(flatten)]
    form: FormArg,
}

pub fn run(args: &EstopArgs) -> Result<(), Failure> {
    let spec = args.link.spec();
    link::built(&spec)?;
    #[cfg(feature = "simulator")]
    if spec == dressform::form::controller::LinkSpec::Sim {
        return on_sim::run(args);
    }
    match control::request_estop(&spec) {
        Ok(Some(owner)) if owner.trusted() => {
            errln!(
                "emergency stop sent by the dressform process {}, which owns the link",
                owner.pid
            );
            return Ok(());
        }
        Ok(Some(owner)) => errln!(
            "warning: the process answering for this link (pid {}) belongs to another user \
             (uid {}): sending the stop on the link too",
            owner.pid,
            owner.uid
        ),
        Ok(None) => {}
        Err(e) => errln!("warning: {e}: sending the stop on the link itself"),
    }
    // No owner answered: the link itself, opened as usual when nobody holds it, else beside
    // whoever does (a stop is never refused for want of a lock).
    match Connection::open(&spec) {
        Ok(connection) => {
            emergency_stop(&connection).map_err(Failure::other)?;
            errln!("emergency stop sent");
        }
        Err(busy) => {
            let gate = shared_stop_gate(&spec).map_err(|e| {
                Failure::other(format!(
                    "{busy}; writing beside the process that holds it failed too: {e} (stop the \
                     form there)"
                ))
            })?;
            gate.emergency_stop(StopCause::Requested).map_err(Failure::other)?;
            errln!("emergency stop sent on the link, beside the process that holds it ({busy})");
        }
    }
    Ok(())
}

/// `estop --sim`: a simulated form started for this command (opened as every command opens
/// `--sim`): stopped, then every node shown.
#[cfg(feature = "simulator")]
mod on_sim {
    use super::{EstopArgs, Failure, link};
    use crate::cli::link::runtime;
    use dressform::form::controller::open::OpenLink;
    use dressform::form::controller::simulated::SimConfig;
    use dressform::form::controller::{LinkSpec, emergency_stop, fault_names};
    use std::time::Duration;

    /// How long the simulated form may take to latch the stop before its nodes are shown
    /// (a few ms; more on a busy machine).
    const SETTLE: Duration = Duration::from_secs(2);

    pub fn run(args: &EstopArgs) -> Result<(), Failure> {
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
}
