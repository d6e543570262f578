//! A synchronised move of the whole form: stage every actuator's target, one SYNC with a
//! common duration, then watch the feedback until every actuator is within tolerance.
//!
//! Packet handling: the targets go out as `update::packets` builds them for the link (two
//! `Targets` halves per node on classic CAN, one `AllTargets` on CAN FD and serial), then the
//! broadcast `Sync`. The duration is the largest `update::shortest_duration_ms` over every
//! actuator's distance (from its last reported position; the full stroke when unknown) and
//! the description's limits, so every actuator stays within its speed and acceleration
//! limits and all arrive together; `--slower` and `--duration` only lengthen it.
//!
//! Safety: targets are [`SafeTarget`]s, and [`node_targets`] is the one place that turns them
//! into wire positions. A fault event or a node in Fault broadcasts `Halt` (the faulty node is
//! already stopping), disables every node and ends the move with the actuator and the reason
//! ([`Session::fault`], [`Session::stop_for_fault`], the same path as during homing). A node
//! that reboots is re-identified, enabled, homed and given its targets again with a new SYNC
//! (at most twice per move), or the move fails clearly.

use std::collections::BTreeMap;
use std::time::Duration;

use firmware_protocol::actuator::MAX_ACTUATORS;
use firmware_protocol::message::Sync;
use firmware_protocol::update::{NodeTargets, packets, shortest_duration_ms};
use firmware_protocol::{Accel, Actuator, Message, NodeId, Packet, Speed};
use serde::Serialize;
use tokio::time::Instant;

use super::session::{Session, SessionError};
use super::transport::Transport;
use crate::form::safety::SafeTarget;
use crate::messages::number;

/// How many times a move resumes after node reboots before it fails.
pub const MAX_RESUMES: usize = 2;

/// One actuator's part in a move.
#[derive(Clone, Debug, PartialEq)]
pub struct PlannedTarget {
    /// Actuator id.
    pub id: String,
    /// Its node.
    pub node: NodeId,
    /// Its index on the node.
    pub actuator: Actuator,
    /// Where it goes.
    pub target: SafeTarget,
    /// Speed limit.
    pub max_speed: Speed,
    /// Acceleration limit.
    pub max_accel: Accel,
    /// Stroke, 0.01 mm (the distance assumed when the position is unknown).
    pub stroke: u16,
}

/// How an actuator ended its move.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ActuatorReport {
    /// Actuator id.
    pub id: String,
    /// Its node's address.
    pub node: u8,
    /// Target, mm.
    pub target_mm: f64,
    /// Last reported position, mm (`None`: unknown).
    pub reached_mm: Option<f64>,
    /// `reached - target`, mm.
    pub error_mm: Option<f64>,
    /// Within tolerance at the end.
    pub within_tolerance: bool,
    /// When it first came within tolerance, from the SYNC, ms.
    pub settled_ms: Option<u64>,
}

/// Progress of a move, for a live display.
#[derive(Clone, Debug, PartialEq)]
pub struct Progress {
    /// Per node: `(address, label, actuators within tolerance, actuators moved, largest
    /// remaining distance in mm)`.
    pub nodes: Vec<NodeProgress>,
    /// Time since the SYNC.
    pub elapsed: Duration,
    /// The move's planned duration.
    pub duration: Duration,
}

/// One node's progress.
#[derive(Clone, Debug, PartialEq)]
pub struct NodeProgress {
    /// Its address.
    pub node: u8,
    /// Its label in the description (or `node N`).
    pub label: String,
    /// Actuators within tolerance.
    pub within: usize,
    /// Actuators in the move.
    pub total: usize,
    /// The largest remaining distance, mm (`None`: a position is unknown).
    pub worst_mm: Option<f64>,
}

/// Why a move failed.
#[derive(Debug, thiserror::Error)]
pub enum MoveError {
    /// The session failed (link, lost node, a fault, an e-stop...).
    #[error(transparent)]
    Session(#[from] SessionError),
    /// A node rebooted more often than the move resumes.
    #[error("node {node} rebooted {times} times during the move; every node halted")]
    Rebooted {
        /// The node.
        node: u8,
        /// How many reboots.
        times: usize,
    },
    /// No duration fits a SYNC ([`Sync::MAX_DURATION_MS`]).
    #[error("{}", too_long(*shortest_ms, *slower, *least_ms))]
    TooLong {
        /// The shortest duration at the actuators' limits, ms.
        shortest_ms: u64,
        /// How many times slower the move was asked to be.
        slower: f64,
        /// The least duration asked, ms.
        least_ms: u64,
    },
}

/// The largest [`MoveOptions::slower`] that can fit a SYNC at all: a move lasts at least
/// 1 ms ([`shortest_duration_ms`] rounds up), a SYNC at most [`Sync::MAX_DURATION_MS`].
pub const MAX_SLOWER: f64 = Sync::MAX_DURATION_MS as f64;

/// Why a move does not fit a SYNC, and with `--slower` how slow it can be.
fn too_long(shortest_ms: u64, slower: f64, least_ms: u64) -> String {
    let max = Sync::MAX_DURATION_MS;
    let limit = format!("more than a SYNC can carry ({max} ms)");
    if shortest_ms > u64::from(max) {
        format!(
            "the move takes {shortest_ms} ms at the actuators' speed and acceleration limits, {limit}"
        )
    } else if least_ms > u64::from(max) {
        format!("the move is to last at least {least_ms} ms, {limit}")
    } else {
        // Rounded down to hundredths, so that the largest shown still fits.
        let most = (f64::from(max) / shortest_ms as f64 * 100.0).floor() / 100.0;
        format!(
            "--slower {} makes the move last {} ms, {limit}: it takes {shortest_ms} ms at the \
             actuators' limits, so --slower can be 1 to {} for this move",
            number(slower),
            number((shortest_ms as f64 * slower).ceil()),
            number(most)
        )
    }
}

/// The wire targets of every node in `plan`: the one place targets become positions.
pub fn node_targets(plan: &[PlannedTarget]) -> Vec<NodeTargets> {
    let mut nodes: BTreeMap<NodeId, [Option<firmware_protocol::Position>; MAX_ACTUATORS]> =
        BTreeMap::new();
    for t in plan {
        nodes.entry(t.node).or_default()[t.actuator.index()] = Some(t.target.position());
    }
    nodes.into_iter().map(|(node, targets)| NodeTargets { node, targets }).collect()
}

/// How far an actuator may be from its last reported position, 0.01 mm: feedback is rounded
/// and noisy (the simulated nodes' noise is clipped at 0.04 mm) while the node plans from
/// where it really is; a move planned this much longer never comes out too short for it.
const FEEDBACK_UNCERTAINTY: u16 = 10;

/// The shortest common duration for `plan` from the last reported positions (each distance
/// lengthened by the feedback's uncertainty), ms.
pub fn shortest_common_duration<T: Transport>(session: &Session<T>, plan: &[PlannedTarget]) -> u64 {
    plan.iter()
        .map(|t| {
            let current =
                session.nodes().get(&t.node).and_then(|s| s.positions[t.actuator.index()]);
            let distance = match current {
                Some(p) => {
                    p.hundredths_mm().abs_diff(t.target.position().hundredths_mm())
                        + FEEDBACK_UNCERTAINTY
                }
                None => t.stroke,
            };
            // Limits of 0 cannot come from a valid description; take the longest then.
            u64::from(shortest_duration_ms(distance, t.max_speed, t.max_accel).unwrap_or(u32::MAX))
        })
        .max()
        .unwrap_or(0)
}

/// How a move is run.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MoveOptions {
    /// Tolerance, mm.
    pub tolerance_mm: f64,
    /// Multiply the shortest duration by this (≥ 1).
    pub slower: f64,
    /// At least this long.
    pub min_duration: Duration,
    /// How long past the planned duration to wait for every actuator to settle.
    pub settle: Duration,
}

/// Stages `plan`, SYNCs and watches until every actuator is within tolerance or the
/// settle time has passed after the planned duration. Returns the duration used and the
/// reports (not within tolerance: see [`ActuatorReport::within_tolerance`]).
pub async fn run<T: Transport>(
    session: &mut Session<T>,
    plan: &[PlannedTarget],
    options: &MoveOptions,
    homing_timeout: Duration,
    progress: &mut dyn FnMut(&Progress),
) -> Result<(u64, Vec<ActuatorReport>, Vec<String>), MoveError> {
    let mut warnings = Vec::new();
    let mut reboots: BTreeMap<NodeId, usize> = BTreeMap::new();
    let (duration, started) = sync(session, plan, options, &mut warnings).await?;
    let mut planned = Duration::from_millis(duration);
    let mut settled: BTreeMap<String, u64> = BTreeMap::new();
    loop {
        let deadline = started + planned + options.settle;
        let tick = (Instant::now() + PROGRESS_PERIOD).min(deadline);
        let tol = options.tolerance_mm;
        let done = session.wait_until(tick, |s| all_within(s, plan, tol)).await?;
        for t in plan {
            if within(session, t, tol) && !settled.contains_key(&t.id) {
                settled.insert(t.id.clone(), started.elapsed().as_millis() as u64);
            }
        }
        progress(&progress_of(session, plan, tol, started.elapsed(), planned));
        // Faults first: they stop everything.
        if let Some(fault) = session.fault(&mut warnings).await? {
            return Err(session.stop_for_fault(fault).await.into());
        }
        let rebooted: Vec<NodeId> =
            session.nodes().iter().filter(|(_, s)| s.rebooted).map(|(&n, _)| n).collect();
        if !rebooted.is_empty() {
            for &node in &rebooted {
                let times = reboots.entry(node).or_default();
                *times += 1;
                if *times > MAX_RESUMES {
                    session.halt_all().await?;
                    return Err(MoveError::Rebooted { node: node.get(), times: *times });
                }
                warnings.push(format!("node {} rebooted during the move; resumed", node.get()));
                if let Some(status) = session.node_mut(node) {
                    status.rebooted = false;
                    status.positions = [None; MAX_ACTUATORS];
                }
                let problems = session.identify(node).await?;
                if !problems.is_empty() {
                    return Err(SessionError::Discovery(problems).into());
                }
                session.enable(node).await?;
            }
            session.wait_ready(&rebooted, homing_timeout).await?;
            let again: Vec<PlannedTarget> =
                plan.iter().filter(|t| rebooted.contains(&t.node)).cloned().collect();
            let (resumed, _) = sync(session, &again, options, &mut warnings).await?;
            // The whole move is watched until the resumed part is done too.
            planned = planned.max(started.elapsed() + Duration::from_millis(resumed));
            continue;
        }
        if done || Instant::now() >= deadline {
            break;
        }
    }
    let reports = plan
        .iter()
        .map(|t| {
            let reached = position_mm(session, t);
            let error = reached.map(|r| r - t.target.mm());
            ActuatorReport {
                id: t.id.clone(),
                node: t.node.get(),
                target_mm: t.target.mm(),
                reached_mm: reached,
                error_mm: error,
                within_tolerance: error
                    .is_some_and(|e| e.abs() <= options.tolerance_mm + ROUNDING_MM),
                settled_ms: settled.get(&t.id).copied(),
            }
        })
        .collect();
    Ok((duration, reports, warnings))
}

/// Stages and SYNCs `plan`; returns the duration (ms) and when the (last) SYNC went out. A
/// fault found before the SYNC (latched since the last move, or while staging) stops the form
/// instead: no node starts a move next to a faulty one.
async fn sync<T: Transport>(
    session: &mut Session<T>,
    plan: &[PlannedTarget],
    options: &MoveOptions,
    warnings: &mut Vec<String>,
) -> Result<(u64, Instant), MoveError> {
    let shortest = shortest_common_duration(session, plan);
    let slower = if options.slower.is_finite() { options.slower.max(1.0) } else { 1.0 };
    let least = u64::try_from(options.min_duration.as_millis()).unwrap_or(u64::MAX);
    let wanted = (shortest as f64 * slower).ceil().max(least as f64);
    if wanted > f64::from(Sync::MAX_DURATION_MS) {
        return Err(MoveError::TooLong { shortest_ms: shortest, slower, least_ms: least });
    }
    let duration_ms = wanted as u16;
    let duration = u64::from(duration_ms);
    let nodes = node_targets(plan);
    let link = session.link();
    let sync = Sync { duration_ms };
    // Targets are not answered: resend a node's until its heartbeat shows them staged (lost
    // frames), then SYNC until no heartbeat shows them still staged. After the last attempt
    // the move goes on; a refusal shows as a warning event and a miss in the report.
    let mut pending = nodes.clone();
    for _ in 0..=CONFIRM_RETRIES {
        let sent = Instant::now();
        for packet in
            packets(&pending, sync, link).filter(|p| !matches!(p.message, Message::Sync(_)))
        {
            session.send(packet).await?;
        }
        let confirmed = |s: &Session<T>, n: &NodeTargets| staged(s, n, sent) == Some(true);
        session
            .wait_until(sent + CONFIRM_TIMEOUT, |s| pending.iter().all(|n| confirmed(s, n)))
            .await?;
        pending.retain(|n| !confirmed(session, n));
        if pending.is_empty() {
            break;
        }
    }
    if let Some(fault) = session.fault(warnings).await? {
        return Err(session.stop_for_fault(fault).await.into());
    }
    let mut sent = Instant::now();
    for _ in 0..=CONFIRM_RETRIES {
        sent = Instant::now();
        session.send(Packet::broadcast(Message::Sync(sync))).await?;
        let started = |s: &Session<T>| nodes.iter().all(|n| staged(s, n, sent) == Some(false));
        if session.wait_until(sent + CONFIRM_TIMEOUT, started).await? {
            break;
        }
    }
    Ok((duration, sent))
}

/// How often a move's progress is reported: 20 times a second looks smooth in a progress bar
/// and costs nothing next to the bus.
const PROGRESS_PERIOD: Duration = Duration::from_millis(50);

/// Slack for rounding when a position is compared with its tolerance: positions and targets
/// are whole hundredths of a mm, so their difference in `f64` may differ from the decimal
/// value in the last bits; a millionth of a micrometre is far below anything the wire carries.
const ROUNDING_MM: f64 = 1e-9;

/// How many times targets and SYNC are resent when heartbeats do not confirm them.
const CONFIRM_RETRIES: usize = 3;
/// How long to wait for heartbeats confirming targets or SYNC: two and a half of the nodes'
/// heartbeat periods ([`firmware_protocol::timing::HEARTBEAT_PERIOD_MS`], 100 ms: 250 ms),
/// two heartbeats and half of one more for a busy host.
const CONFIRM_TIMEOUT: Duration =
    Duration::from_millis(firmware_protocol::timing::HEARTBEAT_PERIOD_MS as u64 * 5 / 2);

/// Whether a heartbeat of `n`'s node received after `since` shows its targets staged
/// (`None`: no such heartbeat yet).
fn staged<T: Transport>(session: &Session<T>, n: &NodeTargets, since: Instant) -> Option<bool> {
    let status = session.nodes().get(&n.node)?;
    let heartbeat = status.heartbeat.filter(|_| status.heartbeat_at.is_some_and(|t| t > since))?;
    let wanted = n.targets.iter().enumerate().filter(|(_, t)| t.is_some());
    Some(
        wanted.clone().count() > 0
            && wanted
                .into_iter()
                .all(|(i, _)| Actuator::new(i as u8).is_some_and(|a| heartbeat.staged.contains(a))),
    )
}

fn position_mm<T: Transport>(session: &Session<T>, t: &PlannedTarget) -> Option<f64> {
    let p = session.nodes().get(&t.node)?.positions[t.actuator.index()]?;
    Some(p.mm())
}

fn within<T: Transport>(session: &Session<T>, t: &PlannedTarget, tolerance_mm: f64) -> bool {
    position_mm(session, t).is_some_and(|p| (p - t.target.mm()).abs() <= tolerance_mm + ROUNDING_MM)
}

/// Every actuator of `plan` is within tolerance and at rest (its node's heartbeat shows it
/// not moving).
fn all_within<T: Transport>(
    session: &Session<T>,
    plan: &[PlannedTarget],
    tolerance_mm: f64,
) -> bool {
    plan.iter().all(|t| {
        let resting = session
            .nodes()
            .get(&t.node)
            .and_then(|s| s.heartbeat)
            .is_some_and(|h| !h.moving.contains(t.actuator));
        resting && within(session, t, tolerance_mm)
    })
}

fn progress_of<T: Transport>(
    session: &Session<T>,
    plan: &[PlannedTarget],
    tolerance_mm: f64,
    elapsed: Duration,
    duration: Duration,
) -> Progress {
    let mut nodes: BTreeMap<NodeId, NodeProgress> = BTreeMap::new();
    for t in plan {
        let entry = nodes.entry(t.node).or_insert_with(|| NodeProgress {
            node: t.node.get(),
            label: session
                .form()
                .nodes
                .iter()
                .find(|n| n.address == t.node.get())
                .and_then(|n| n.label.clone())
                .unwrap_or_else(|| format!("node {}", t.node.get())),
            within: 0,
            total: 0,
            worst_mm: Some(0.0),
        });
        entry.total += 1;
        if within(session, t, tolerance_mm) {
            entry.within += 1;
        }
        let remaining = position_mm(session, t).map(|p| (p - t.target.mm()).abs());
        entry.worst_mm = match (entry.worst_mm, remaining) {
            (Some(a), Some(b)) => Some(a.max(b)),
            _ => None,
        };
    }
    Progress { nodes: nodes.into_values().collect(), elapsed, duration }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_move_too_long_for_a_sync_says_how_slow_it_can_be() {
        let message = too_long(4642, 1000.0, 0);
        assert!(message.starts_with("--slower 1000 makes the move last 4642000 ms"), "{message}");
        assert!(message.ends_with("--slower can be 1 to 14.11 for this move"), "{message}");
        // The largest factor shown fits, for any shortest duration.
        for shortest in [1, 3, 7, 4641, 4642, 30_000, 65_535] {
            let message = too_long(shortest, MAX_SLOWER, 0);
            let most: f64 =
                message.rsplit("1 to ").next().unwrap().split(' ').next().unwrap().parse().unwrap();
            assert!(
                (shortest as f64 * most).ceil() <= f64::from(Sync::MAX_DURATION_MS),
                "{message}"
            );
        }
        assert!(
            too_long(70_000, 1.0, 0).contains("at the actuators' speed and acceleration limits")
        );
        assert!(too_long(10, 1.0, 70_000).contains("at least 70000 ms"));
    }
}
