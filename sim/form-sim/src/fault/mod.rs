//! Fault injection, configured per run by one spec string (`dressform sim --faults <spec>`).
//!
//! ```text
//! spec           = [ item { "," item } ]        (spaces around items are ignored)
//! item           = "seed=" integer              seed of the random faults (default 0)
//!                | "drop=" probability          each frame is lost
//!                | "corrupt=" probability       each frame is hit by a bit error
//!                | "delay=" duration            each frame arrives this much later
//!                | "busoff" window              the bus carries nothing
//!                | "node" address ":" node-fault
//!                | actuator-id ":" actuator-fault
//! node-fault     = "reboot@" time               the node's controller restarts
//!                | "silent" window              cut off the bus: hears and says nothing
//!                | "slow=" duration [ window ]  answers requests this much later
//! actuator-fault = "stall@" time                the mechanism jams for good
//!                | "encoder@" time              the encoder fails for good
//! window         = "@" time [ ".." time ]       from, until (default: to the end)
//! time, duration = number unit,  unit = "us" | "ms" | "s"      (250ms, 1.5s)
//! probability    = number in [0, 1)
//! ```
//!
//! Example: `drop=0.05,corrupt=0.01,delay=2ms,busoff@3s..3.2s,node3:reboot@1.5s,`
//! `node2:silent@2s..2.5s,node5:slow=40ms,chest-l1:stall@0.5s,seed=7`.
//!
//! Times count from the start of the run (the creation of the bus or of the served form).
//! `node3` is the node at bus address 3; actuators are named by their form id. Random faults
//! draw from a ChaCha8 stream seeded by `seed`, one draw per frame in bus order, so a run
//! under tokio's paused clock repeats exactly.
//!
//! What each fault does:
//!
//! * **drop**: the frame is lost at every receiver (an overrun). On CAN it still took its
//!   bus time and the sender saw it acknowledged.
//! * **corrupt**: on CAN a bit error is caught by the CRC: an error frame follows the broken
//!   frame and the sender retransmits it automatically (bus time and latency, no loss),
//!   logged as an error frame. On serial one bit of the frame flips and the receiver's CRC
//!   drops it.
//! * **delay**: every frame reaches the receivers this much later (a slow adapter).
//! * **busoff**: during the window every transmission fails (on CAN the senders' queues are
//!   flushed, `send` returns [`BusError::BusOff`](crate::bus::can::BusError::BusOff)).
//! * **reboot**: the node's controller restarts (see [`Node::reboot`](crate::node::Node::reboot)).
//! * **silent**: the node neither hears nor sends (a pulled connector); its watchdog trips
//!   if it was enabled.
//! * **slow**: everything the node sends in answer to a frame goes out later; cyclic frames
//!   keep their period.
//! * **stall** and **encoder**: see [`ActuatorFault`].

mod schedule;
mod spec;

pub use schedule::{BusFaultInjector, FrameFault, NodeEvent, NodeSchedule};
pub use spec::FaultSpecError;

use std::time::Duration;

use crate::node::ActuatorFault;

/// A run's faults, parsed from a spec string (`"drop=0.01,node3:reboot@2s".parse()`).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct FaultSpec {
    /// Seed of the random faults.
    pub seed: u64,
    /// Faults of the bus (or serial line).
    pub bus: BusFaults,
    /// Faults of nodes.
    pub nodes: Vec<NodeFaultAt>,
    /// Faults of actuators.
    pub actuators: Vec<ActuatorFaultAt>,
}

/// Faults of the bus itself.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct BusFaults {
    /// Probability that a frame is lost, [0, 1).
    pub drop: f64,
    /// Probability that a frame is hit by a bit error, [0, 1).
    pub corrupt: f64,
    /// Extra latency of every frame.
    pub delay: Duration,
    /// When the bus is off.
    pub bus_off: Vec<Window>,
}

/// A stretch of the run: from `from` until `until` (or the end).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Window {
    /// Start, from the start of the run.
    pub from: Duration,
    /// End, from the start of the run; `None`: to the end of the run.
    pub until: Option<Duration>,
}

impl Window {
    /// Whether `t` (from the start of the run) is inside.
    pub fn contains(&self, t: Duration) -> bool {
        t >= self.from && self.until.is_none_or(|until| t < until)
    }
}

/// A fault of a node.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum NodeFault {
    /// Its controller restarts at the window's start.
    Reboot,
    /// It hears and says nothing during the window.
    Silent,
    /// It answers this much later during the window.
    Slow(Duration),
}

/// A node fault and when.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct NodeFaultAt {
    /// The node's bus address.
    pub node: u8,
    /// The fault.
    pub fault: NodeFault,
    /// When (a reboot happens at `window.from`).
    pub window: Window,
}

/// An actuator fault and when.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ActuatorFaultAt {
    /// The actuator's id in the form.
    pub actuator: String,
    /// The fault.
    pub fault: ActuatorFault,
    /// When it happens, from the start of the run (it lasts to the end).
    pub at: Duration,
}
