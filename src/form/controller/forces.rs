//! What the form feels at rest (protocol 1.1): every actuator's measured force, averaged over
//! a window after a move, so a fit test reads a garment's load without the sensors' noise.
//!
//! Nodes send forces with their feedback (every 20 ms on CAN, with every poll on serial);
//! [`read_forces`] keeps the session alive for the window, takes every fresh reading, and
//! watches for faults meanwhile: an actuator over its force limit (`OVER_FORCE`) stops the
//! form as any fault does.

use std::collections::BTreeMap;
use std::time::Duration;

use firmware_protocol::NodeId;
use firmware_protocol::actuator::MAX_ACTUATORS;
use serde::Serialize;
use tokio::time::Instant;

use super::session::{Session, SessionError};
use super::transport::Transport;

/// How long forces are read at rest by default: 25 readings at the 20 ms feedback period,
/// which divides the sensors' noise by 5.
pub const DEFAULT_FORCE_WINDOW: Duration = Duration::from_millis(500);

/// How often the window looks for fresh readings: the feedback period, so no reading of a
/// node is missed and none is taken twice.
const SAMPLE_PERIOD: Duration =
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
/// the way go to `warnings`. A fault meanwhile stops the form ([`Session::stop_for_fault`]).
/// Actuators without a reading are left out.
pub async fn read_forces<T: Transport>(
    session: &mut Session<T>,
    window: Duration,
    warnings: &mut Vec<String>,
) -> Result<BTreeMap<String, ForceSample>, SessionError> {
    let mut sums: BTreeMap<(NodeId, usize), (f64, f64, u32)> = BTreeMap::new();
    let mut seen: BTreeMap<NodeId, u64> =
        session.nodes().iter().map(|(&n, s)| (n, s.force_readings)).collect();
    let end = Instant::now() + window;
    while Instant::now() < end {
        let tick = (Instant::now() + SAMPLE_PERIOD).min(end);
        session.wait_until(tick, |_| false).await?;
        if let Some(fault) = session.fault(warnings).await? {
            return Err(session.stop_for_fault(fault).await);
        }
        for (&node, status) in session.nodes() {
            if seen.get(&node) == Some(&status.force_readings) {
                continue;
            }
            seen.insert(node, status.force_readings);
            for (index, force) in status.forces.iter().enumerate().take(MAX_ACTUATORS) {
                if let Some(f) = force {
                    let entry = sums.entry((node, index)).or_default();
                    *entry = (entry.0 + f.n(), entry.1 + f.n() * f.n(), entry.2 + 1);
                }
            }
        }
    }
    let form = session.form();
    Ok(sums
        .into_iter()
        .filter_map(|((node, index), (sum, squares, count))| {
            let axis = form.actuator_at(node, firmware_protocol::Actuator::new(index as u8)?)?;
            let n = f64::from(count);
            let mean = sum / n;
            let sd = (squares / n - mean * mean).max(0.0).sqrt();
            Some((axis.id.to_string(), ForceSample { mean_n: mean, sd_n: sd, readings: count }))
        })
        .collect())
}
