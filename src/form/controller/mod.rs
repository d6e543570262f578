//! The host controller: drives the robotic form over serial, CAN, slcan or the in-process
//! simulated bus.
//!
//! [`drive`] runs one shape change: check the set-points against the form description
//! (nothing outside a stroke, see [`crate::form::safety`]), discover every node and check it against the
//! description ([`session`]), enable and home, one synchronised move with live progress and
//! per-actuator report ([`motion`]), then disable (the drives hold the panels).
//!
//! | module | what it holds |
//! |---|---|
//! | [`transport`] | the [`Transport`] trait; serial, slcan, SocketCAN and simulated links; the [`Gate`] every packet goes through, and the e-stop on it from any thread (`transport::gate`) |
//! | [`claim`] | the form claimed for a whole command: e-stops latched at its start recorded, the link kept alive while it computes, no later e-stop cleared |
//! | [`control`] | the local control endpoint: `dressform estop` reaching the link's owner |
//! | [`session`] | discovery, fault reset, enable/home, heartbeats and polls, liveness, faults, reboots |
//! | [`motion`] | staging, the common SYNC duration, watching feedback, the report |
//! | [`faults`] | states, faults, events and refusals in words; which faults the host clears |
//! | [`open`] | opening the link a [`LinkSpec`] names, starting the simulated form for `--sim` |
//! | [`simulated`] | the whole thing on the in-process simulated form |
//!
//! Safety rules, all enforced here: targets come only from [`SafeTarget`]s built against the
//! description's strokes (checked against what every node reports); the SYNC duration is
//! never shorter than the shortest feasible for every actuator; a fault (during homing or a
//! move) broadcasts `Halt` and disables every node; a lost node, a stalled link, a reboot that
//! cannot be resumed or a failed link end the move with an error; an e-stop (another terminal, a signal) latches the link's [`Gate`]
//! and broadcasts `EmergencyStop` without waiting for the session; a hardware fault is never
//! cleared without the caller's say-so.

pub mod claim;
pub mod control;
pub mod faults;
pub mod motion;
pub mod open;
pub mod session;
#[cfg(feature = "simulator")]
pub mod simulated;
// Without the simulator: its types, and the refusal to start one.
#[cfg(not(feature = "simulator"))]
#[path = "no_simulator.rs"]
pub mod simulated;
pub mod transport;

use std::collections::BTreeMap;
use std::time::Duration;

use firmware_protocol::NodeId;
use firmware_protocol::drive::Faults;
use form_description::FormDescription;
use serde::Serialize;
use tokio::time::Instant;

pub use crate::form::safety::SafeTarget;
pub use claim::Claim;
pub use faults::{fault_names, state_name};
pub use motion::{ActuatorReport, MoveError, NodeProgress, PlannedTarget, Progress};
pub use session::{Cleared, NodeProblem, Session, SessionError};
pub use transport::{Connection, Gate, LinkSpec, StopCause, Transport, TransportError};

use crate::form::setpoints::{OutOfStroke, SetPoints};

/// Set-points clamped into the stroke: `(actuator id, asked mm, used mm)`.
pub type Clamped = Vec<(String, f64, f64)>;

/// The default tolerance, mm.
pub const DEFAULT_TOLERANCE_MM: f64 = 0.1;

/// How long past a move's planned duration the actuators may take to arrive by default: a
/// drive's position loop settles in tens of milliseconds; the rest is margin for a node that
/// was busy or a host under load.
pub const DEFAULT_SETTLE: Duration = Duration::from_secs(2);

/// How long homing may take by default: a node homes by creeping to its switch at its homing
/// speed (5 mm/s by default), so the reference form's longest stroke, 60 mm, takes 12 s; 30 s
/// leaves room for a slower homing speed and a node homed last.
pub const DEFAULT_HOMING_TIMEOUT: Duration = Duration::from_secs(30);

/// How a drive runs.
#[derive(Clone, Debug)]
pub struct DriveOptions {
    /// Clamp out-of-stroke set-points instead of refusing them.
    pub clamp: bool,
    /// An actuator within this of its target has arrived, mm (default 0.1).
    pub tolerance_mm: f64,
    /// Multiply the shortest duration by this (default 1: the shortest; values below 1
    /// count as 1).
    pub slower: f64,
    /// The move lasts at least this long (default 0: the shortest).
    pub min_duration: Duration,
    /// How long past the planned duration to wait for every actuator (default 2 s).
    pub settle: Duration,
    /// How long homing may take (default 30 s).
    pub homing_timeout: Duration,
    /// Clear latched hardware faults (a jam, an overcurrent, a broken encoder...) at start;
    /// without it only an emergency stop and a host timeout are cleared (default false).
    pub reset_faults: bool,
}

impl Default for DriveOptions {
    fn default() -> Self {
        Self {
            clamp: false,
            tolerance_mm: DEFAULT_TOLERANCE_MM,
            slower: 1.0,
            min_duration: Duration::ZERO,
            settle: DEFAULT_SETTLE,
            homing_timeout: DEFAULT_HOMING_TIMEOUT,
            reset_faults: false,
        }
    }
}

/// What a drive did.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct DriveReport {
    /// The form's name.
    pub form: String,
    /// The link (`/dev/ttyUSB0`, `can0`, `simulated bus`).
    pub device: String,
    /// The SYNC's duration, ms.
    pub duration_ms: u64,
    /// From the SYNC to the end of watching, ms.
    pub elapsed_ms: u64,
    /// Every actuator of the set-points, in id order.
    pub actuators: Vec<ActuatorReport>,
    /// Every actuator of the form whose position was known at the end, mm (those the
    /// set-points leave out included): what the form's shape is computed from.
    pub positions_mm: BTreeMap<String, f64>,
    /// Set-points clamped into the stroke: `(id, asked mm, used mm)`.
    pub clamped: Clamped,
    /// Faults cleared at the start, warnings from the nodes (a move too short, ...) and
    /// resumed reboots.
    pub warnings: Vec<String>,
}

impl DriveReport {
    /// Every actuator arrived within tolerance.
    pub fn converged(&self) -> bool {
        self.actuators.iter().all(|a| a.within_tolerance)
    }
}

/// Why a drive failed.
#[derive(Debug, thiserror::Error)]
pub enum DriveError {
    /// The set-points ask for positions outside the stroke (nothing was sent).
    #[error(transparent)]
    OutOfStroke(#[from] OutOfStroke),
    /// The session failed.
    #[error(transparent)]
    Session(#[from] SessionError),
    /// The move failed.
    #[error(transparent)]
    Move(#[from] MoveError),
    /// Some actuators did not arrive within tolerance in time.
    #[error("{} actuators not within tolerance after {} ms: {}", .0.actuators.iter().filter(|a| !a.within_tolerance).count(), .0.elapsed_ms, crate::messages::list(.0.actuators.iter().filter(|a| !a.within_tolerance).map(|a| &a.id)))]
    NotReached(Box<DriveReport>),
}

/// The plan of a move: every set-point's actuator with its checked target and limits.
pub fn plan(
    form: &FormDescription,
    setpoints: &SetPoints,
    clamp: bool,
) -> Result<(Vec<PlannedTarget>, Clamped), OutOfStroke> {
    let checked = setpoints.check(form, clamp)?;
    let plan = checked
        .targets
        .iter()
        .filter_map(|(id, &target)| {
            let spec = form.actuator(id)?;
            Some(PlannedTarget {
                id: id.clone(),
                node: spec.node_id()?,
                actuator: spec.actuator()?,
                target,
                max_speed: spec.max_speed(),
                max_accel: spec.max_accel(),
                stroke: spec.stroke().hundredths_mm(),
            })
        })
        .collect();
    Ok((plan, checked.clamped))
}

/// Drives the form to `setpoints`: checks them (refusing or clamping out-of-stroke
/// positions before anything is sent), claims the form ([`Claim::take`]: discovers and
/// checks every node), then drives it ([`Claim::drive`]): clears latched faults as
/// [`DriveOptions::reset_faults`] allows, enables and homes, moves every actuator together,
/// watches until all are within tolerance, then disables. `progress` is called about every
/// 50 ms during the move.
pub async fn drive<T: Transport>(
    transport: T,
    form: &FormDescription,
    setpoints: &SetPoints,
    options: &DriveOptions,
    progress: impl FnMut(&Progress),
) -> Result<DriveReport, DriveError> {
    plan(form, setpoints, options.clamp)?;
    Claim::take(transport, form).await?.drive(setpoints, options, progress).await
}

/// One note per kind of fault cleared: `cleared the latched emergency stop on nodes 1, 2, 3`.
fn cleared_notes(cleared: &[Cleared]) -> Vec<String> {
    let mut by_kind: BTreeMap<String, Vec<String>> = BTreeMap::new();
    for c in cleared {
        by_kind.entry(faults::describe(c.faults)).or_default().push(c.node.address.to_string());
    }
    by_kind
        .into_iter()
        .map(|(what, nodes)| format!("cleared the latched {what} on node(s) {}", nodes.join(", ")))
        .collect()
}

/// Every fault flag, the reserved bits included: what `reset_faults` may clear.
const ANY_FAULT: Faults = Faults::from_bits_retain(u16::MAX);

/// Every actuator of the form whose position the session knows, mm.
fn positions_of<T: Transport>(session: &Session<T>) -> BTreeMap<String, f64> {
    session
        .form()
        .actuators
        .iter()
        .filter_map(|a| {
            let p = session.nodes().get(&a.node_id()?)?.positions[a.actuator()?.index()]?;
            Some((a.id.clone(), p.mm()))
        })
        .collect()
}

/// One node as `dressform status` shows it.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct NodeReport {
    /// Its address.
    pub node: u8,
    /// `Identity` answered.
    pub identified: bool,
    /// Its protocol version, `major.minor`.
    pub protocol: Option<String>,
    /// Its firmware version.
    pub firmware: Option<String>,
    /// Its drive state.
    pub state: Option<String>,
    /// Its latched faults (`EMERGENCY_STOP`, ...).
    pub faults: Vec<String>,
    /// Its latched faults in words, if any.
    pub fault_words: Option<String>,
    /// Actuator id → position, mm (`None`: not homed or not reported).
    pub positions_mm: Vec<(String, Option<f64>)>,
    /// Problems against the description.
    pub problems: Vec<String>,
}

/// The state of every node of `form`, without changing it: identifies each (problems are
/// reported, not fatal), then listens (and polls, on serial) for `listen`.
pub async fn status<T: Transport>(
    transport: T,
    form: &FormDescription,
    listen: Duration,
) -> Result<Vec<NodeReport>, SessionError> {
    let mut session = Session::new(transport, form);
    let mut problems: Vec<(NodeId, Vec<NodeProblem>)> = Vec::new();
    let nodes: Vec<NodeId> = form.node_ids().collect();
    for &node in &nodes {
        problems.push((node, session.identify(node).await?));
    }
    session.wait_until(Instant::now() + listen, |_| false).await?;
    let reports = nodes
        .iter()
        .zip(problems)
        .map(|(&node, (_, problems))| {
            let status = session.nodes().get(&node).cloned().unwrap_or_default();
            let heartbeat = status.heartbeat;
            NodeReport {
                node: node.get(),
                identified: status.identity.is_some(),
                protocol: status
                    .identity
                    .map(|i| format!("{}.{}", i.protocol.major, i.protocol.minor)),
                firmware: status.identity.map(|i| {
                    format!("{}.{}.{}", i.firmware.major, i.firmware.minor, i.firmware.patch)
                }),
                state: heartbeat.map(|h| state_name(h.state).to_string()),
                fault_words: heartbeat
                    .map(|h| faults::describe(h.faults))
                    .filter(|_| heartbeat.is_some_and(|h| !h.faults.is_empty())),
                faults: heartbeat.map(|h| fault_names(h.faults)).unwrap_or_default(),
                positions_mm: form
                    .actuators_of(node)
                    .iter()
                    .map(|a| {
                        let p = a.actuator().and_then(|i| status.positions[i.index()]);
                        (a.id.clone(), p.map(|p| p.mm()))
                    })
                    .collect(),
                problems: problems.iter().map(ToString::to_string).collect(),
            }
        })
        .collect();
    Ok(reports)
}

/// What `dressform reset` found and did.
#[derive(Clone, Debug, PartialEq)]
pub struct ResetReport {
    /// Nodes that differ from the description (reset anyway, as far as they answer).
    pub problems: Vec<NodeProblem>,
    /// Every node that was in Fault: what it held, what remains.
    pub cleared: Vec<Cleared>,
}

/// Clears every latched fault whose cause is gone: identifies the nodes (differences from
/// the description are reported, not fatal), then sends FaultReset to every node in Fault.
pub async fn reset<T: Transport>(
    transport: T,
    form: &FormDescription,
) -> Result<ResetReport, SessionError> {
    let mut session = Session::new(transport, form);
    let mut problems = Vec::new();
    let nodes: Vec<NodeId> = form.node_ids().collect();
    for node in nodes {
        problems.extend(session.identify(node).await?);
    }
    let cleared = session.reset_faults(|_| ANY_FAULT).await?;
    Ok(ResetReport { problems, cleared })
}

/// Broadcasts an emergency stop on a link this process opened (see [`Gate`]): every
/// node stops, powers off and latches `EMERGENCY_STOP` until a FaultReset.
pub fn emergency_stop<T: Transport>(transport: &T) -> Result<(), TransportError> {
    transport.gate().emergency_stop(StopCause::Requested)
}
