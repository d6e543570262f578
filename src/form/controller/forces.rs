//! What the form feels at rest (protocol 1.1): every actuator's measured force, averaged over
//! a window after a move, so a fit test reads a garment's load without the sensors' noise.
//!
//! Nodes send forces with their feedback (every 20 ms on CAN, with every poll on serial); the
//! session adds up every reading as its frame arrives ([`super::session::ForceSum`]).
//! [`read_forces`] clears the sums, keeps the session alive for the window and watches for
//! faults meanwhile: an actuator over its force limit (`OVER_FORCE`) stops the form as any
//! fault does, and a node that reboots (its positions and limits lost) voids the reading.

use std::collections::BTreeMap;
use std::time::Duration;

use firmware_protocol::actuator::MAX_ACTUATORS;
use firmware_protocol::{Actuator, NodeId};
use serde::Serialize;
use tokio::time::Instant;

use super::session::{Session, SessionError};
use super::transport::Transport;

/// How long forces are read at rest by default: 25 readings at the 20 ms feedback period,
/// which divides the sensors' noise by 5.
pub const DEFAULT_FORCE_WINDOW: Duration = Duration::from_millis(500);

/// How often the window looks for faults and reboots: a feedback period.
const CHECK_PERIOD: Duration =
    Duration::from_millis(firmware_protocol::timing::FEEDBACK_PERIOD_MS as u64);

/// One actuator's force over the window.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct ForceSample {
    /// The mean, N (positive: the load pushes the panel in).
    pub mean_n: f64,
    /// The readings' standard deviation, N.
    pub sd_n: f64,
    /// How many readings.
    pub readings: u32,
}

/// The nodes of the session's form that measure no force (protocol 1.0), by address.
pub fn without_force<T: Transport>(session: &Session<T>) -> Vec<u8> {
    session.form().node_ids().filter(|&n| !session.measures_force(n)).map(NodeId::get).collect()
}

/// Reads every actuator's force for `window`, keeping the session alive; warnings found on
/// the way go to `warnings`. Every reading of the window counts once (each frame as it
/// arrives). A fault meanwhile stops the form ([`Session::stop_for_fault`]); a node that
/// reboots voids the reading ([`SessionError::RebootedWhileReading`]). Actuators without a
/// reading are left out.
pub async fn read_forces<T: Transport>(
    session: &mut Session<T>,
    window: Duration,
    warnings: &mut Vec<String>,
) -> Result<BTreeMap<String, ForceSample>, SessionError> {
    let nodes: Vec<NodeId> = session.nodes().keys().copied().collect();
    for &node in &nodes {
        if let Some(status) = session.node_mut(node) {
            status.force_sums = Default::default();
        }
    }
    let end = Instant::now() + window;
    while Instant::now() < end {
        let tick = (Instant::now() + CHECK_PERIOD).min(end);
        session.wait_until(tick, |_| false).await?;
        if let Some(fault) = session.fault(warnings).await? {
            return Err(session.stop_for_fault(fault).await);
        }
        if let Some((&node, _)) = session.nodes().iter().find(|(_, s)| s.rebooted) {
            let name = session.node_name(node).to_string();
            session.halt_all().await?;
            session.disable_all().await?;
            return Err(SessionError::RebootedWhileReading(name));
        }
    }
    let form = session.form();
    let mut samples = BTreeMap::new();
    for (&node, status) in session.nodes() {
        for (index, sum) in status.force_sums.iter().enumerate().take(MAX_ACTUATORS) {
            let Some(axis) = Actuator::new(index as u8).and_then(|a| form.actuator_at(node, a))
            else {
                continue;
            };
            if sum.count == 0 {
                continue;
            }
            let n = f64::from(sum.count);
            let mean = sum.sum / n;
            let sd = (sum.squares / n - mean * mean).max(0.0).sqrt();
            samples.insert(
                axis.id.to_string(),
                ForceSample { mean_n: mean, sd_n: sd, readings: sum.count },
            );
        }
    }
    Ok(samples)
}
