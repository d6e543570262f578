//! Why a session failed: one error per way a session ends, worded for people (the node, the
//! request, the fault in words). The rules behind them are in `docs/controller-and-safety.md`
//! ("Driving the form", "Recovery", "The pseudo-terminal's own stalls").

use std::time::Duration;

use firmware_protocol::drive::AckStatus;

use super::NodeProblem;
use super::liveness::{LINK_STALL_LIMIT, NODE_LOST_AFTER, POLLS_LOST};
use crate::form::controller::faults::{self, Fault};
use crate::form::controller::transport::{StopCause, TransportError};

/// Why a session failed.
#[derive(Debug, thiserror::Error)]
pub enum SessionError {
    /// The link failed.
    #[error(transparent)]
    Transport(#[from] TransportError),
    /// The nodes do not match the description.
    #[error("the form does not match its description:\n  {}", list(.0))]
    Discovery(Vec<NodeProblem>),
    /// A node refused the force limit the description sets (above its actuators' rated
    /// force); nothing was enabled.
    #[error("{node}: refused the force limit of {limit_n} N{}: lower `force_limit_n` in the form description", .rated_n.map_or(String::new(), |r| format!(", above its rated force of {r} N")))]
    ForceLimit {
        /// The node, by name.
        node: String,
        /// The limit asked for, N.
        limit_n: f64,
        /// The actuator's rated force, N, if the node said.
        rated_n: Option<f64>,
    },
    /// Forces were being read and a node rebooted: the reading is void (its actuators'
    /// positions and limits were lost).
    #[error("{0} rebooted while the forces were read: the reading is void; test again")]
    RebootedWhileReading(String),
    /// A node refused a request.
    #[error("node {node}: {request} refused: {}{hint}", faults::refusal_words(*.status))]
    Refused {
        /// The node.
        node: u8,
        /// The request.
        request: &'static str,
        /// Its answer.
        status: AckStatus,
        /// What is known about why.
        hint: String,
    },
    /// A node did not answer a request, retries included.
    #[error("node {node}: no answer to {request} after {attempts} attempts")]
    NoAnswer {
        /// The node.
        node: u8,
        /// The request.
        request: &'static str,
        /// How many times it was sent.
        attempts: u8,
    },
    /// A node went silent (CAN: no heartbeat for [`NODE_LOST_AFTER`] of listening time, the
    /// link's stalls left out).
    #[error("node {node}: lost: nothing heard for {} ms (limit {} ms)", silent.as_millis(), NODE_LOST_AFTER.as_millis())]
    NodeLost {
        /// The node.
        node: u8,
        /// How long it had been silent when noticed.
        silent: Duration,
    },
    /// A serial node left [`POLLS_LOST`] polls in a row unanswered.
    #[error("node {node}: lost: {POLLS_LOST} polls in a row unanswered (nothing heard for {} ms)", silent.as_millis())]
    NodeUnanswered {
        /// The node.
        node: u8,
        /// How long it had been silent when noticed.
        silent: Duration,
    },
    /// The whole link carried nothing from any node for longer than [`LINK_STALL_LIMIT`]:
    /// the link stalled (or the form lost power), which is no one node's loss.
    #[error("the link carried nothing from any node for {:.1} s (limit {} s): the adapter, cable or bus stalled, or the form lost power", quiet.as_secs_f64(), LINK_STALL_LIMIT.as_secs())]
    LinkStalled {
        /// How long it had carried nothing when noticed (or when it spoke again).
        quiet: Duration,
    },
    /// Homing did not finish in time.
    #[error("homing did not finish within {} s: {}", .timeout.as_secs(), crate::messages::list(.nodes))]
    Homing {
        /// How long the host waited.
        timeout: Duration,
        /// The nodes still homing, with their state in words.
        nodes: Vec<String>,
    },
    /// A fault stopped the form (every node was halted).
    #[error("fault on {0}; every node halted")]
    Fault(Fault),
    /// Nodes hold latched faults the caller does not allow the host to clear.
    #[error("latched faults the host does not clear on its own:\n  {}", .0.join("\n  "))]
    Latched(Vec<String>),
    /// A FaultReset did not clear a node's faults (their cause remains).
    #[error("faults not cleared (their cause remains):\n  {}", .0.join("\n  "))]
    NotCleared(Vec<String>),
    /// An e-stop latched on these nodes (addresses) after the command claimed the form (see
    /// [`crate::form::controller::claim`]): the command ends without clearing it.
    #[error("stopped by an e-stop latched on node(s) {} after this command started (not cleared: check the form, then `dressform reset`)", crate::messages::list(.0))]
    StoppedSinceStart(Vec<u8>),
    /// The link was e-stopped (another terminal, a signal): the session sent nothing more.
    #[error("stopped by {0}: emergency stop sent to every node")]
    Stopped(StopCause),
}

fn list(problems: &[NodeProblem]) -> String {
    let lines: Vec<String> = problems.iter().map(ToString::to_string).collect();
    lines.join("\n  ")
}
