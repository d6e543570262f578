//! A session with the form's nodes: discovery against the form description, enabling, homing,
//! liveness both ways, and what every node last said.
//!
//! | file | its job |
//! |---|---|
//! | `mod.rs` | the [`Session`], what it knows of every node ([`NodeStatus`]), taking in packets, waiting |
//! | `error.rs` | why a session failed ([`SessionError`]) |
//! | `requests.rs` | addressed requests, their retries and answers ([`ATTEMPTS`]) |
//! | `liveness.rs` | host heartbeats and polls, a node's silence told from the link's ([`NODE_LOST_AFTER`], [`LINK_STALL_LIMIT`]) |
//! | `discovery.rs` | every node identified and checked against the description ([`NodeProblem`]) |
//! | `fault_handling.rs` | faults found, the form stopped for them, latched faults cleared ([`Cleared`]) |
//! | `enable.rs` | enabling, homing, waiting until ready, disabling |
//!
//! Packet handling (here): every received packet updates its node's [`NodeStatus`] (heartbeat,
//! positions, forces, identity, events); packets from addresses the description lacks are recorded as
//! unexpected nodes; a node whose heartbeat falls back to Disabled unasked (or forgets its
//! homes) has rebooted. Received packets are always taken before silence is judged, and while
//! the session waits, heartbeats and polls go on (see `liveness.rs`).
//!
//! Safety: the session never sends targets itself; `motion` builds them from
//! [`SafeTarget`](crate::form::safety::SafeTarget)s only. Every packet goes through the link's
//! [`Gate`](crate::form::controller::transport::Gate): once the link is e-stopped, from any
//! thread, nothing else is sent and the session ends with [`SessionError::Stopped`]. Every way
//! out of a failed move goes through a broadcast `Halt` or `EmergencyStop`. The rules are those
//! of `docs/controller-and-safety.md` ("Safety", "The e-stop").

mod discovery;
mod enable;
mod error;
mod fault_handling;
mod liveness;
mod requests;

use std::collections::BTreeMap;
use std::time::Duration;

use firmware_protocol::actuator::MAX_ACTUATORS;
use firmware_protocol::drive::DriveState;
use firmware_protocol::message::{Capabilities, Emergency, Heartbeat, Identity, Positions8};
use firmware_protocol::{Address, Force, Link, Message, NodeId, Packet, Position};
use form_description::FormDescription;
use tokio::sync::watch;
use tokio::time::{Instant, sleep_until};

use super::faults::NodeName;
use super::transport::{StopCause, Transport, TransportError};

pub use discovery::NodeProblem;
pub use error::SessionError;
pub use fault_handling::Cleared;
pub use liveness::{
    HEARTBEAT_PERIOD, LINK_STALL_LIMIT, LONGEST_COUNTED_GAP, ListeningClock, NODE_LOST_AFTER,
    POLL_PERIOD, POLLS_LOST,
};
pub use requests::ATTEMPTS;
use requests::answer_timeout;

/// What the host knows about one node.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct NodeStatus {
    /// Its `Identity`, once identified.
    pub identity: Option<Identity>,
    /// Its `Capabilities`, once identified.
    pub capabilities: Option<Capabilities>,
    /// Its last heartbeat.
    pub heartbeat: Option<Heartbeat>,
    /// When its last heartbeat came.
    pub heartbeat_at: Option<Instant>,
    /// Its actuators' last reported positions (`None`: unknown).
    pub positions: [Option<Position>; MAX_ACTUATORS],
    /// Its actuators' last measured forces (protocol 1.1; `None`: not measured).
    pub forces: [Option<Force>; MAX_ACTUATORS],
    /// Every force reading of each actuator since the sums were last cleared (see
    /// `controller::forces`): each frame's readings counted once.
    pub force_sums: [ForceSum; MAX_ACTUATORS],
    /// When it was last heard from, in the session's listening time.
    pub heard: Option<Duration>,
    /// The link's stalls excused up to then (see [`Session::excused`]): later stalls are
    /// left out of its silence.
    pub excused_at: Duration,
    /// Polls in a row it left unanswered (serial), since it was last heard from.
    pub unanswered_polls: u32,
    /// Its `Emergency` events not yet handled, oldest first.
    pub events: Vec<Emergency>,
    /// It fell back to Disabled with its homes forgotten since this was last cleared.
    pub rebooted: bool,
}

/// The sum of an actuator's force readings, N, to average them.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ForceSum {
    /// The readings' sum.
    pub sum: f64,
    /// Their squares' sum.
    pub squares: f64,
    /// How many.
    pub count: u32,
}

impl ForceSum {
    fn add(&mut self, force: Option<Force>) {
        if let Some(f) = force {
            self.sum += f.n();
            self.squares += f.n() * f.n();
            self.count += 1;
        }
    }
}

/// A session with the nodes of one form over one link.
#[derive(Debug)]
pub struct Session<T> {
    transport: T,
    form: FormDescription,
    nodes: BTreeMap<NodeId, NodeStatus>,
    unexpected: Vec<u8>,
    next_service: Instant,
    next_heartbeat: Instant,
    watch_liveness: bool,
    stopped: watch::Receiver<Option<StopCause>>,
    clock: ListeningClock,
    /// When any node was last heard from, in listening time.
    heard_any: Duration,
    /// The link's ended stalls so far, in listening time (see [`Session::excused`]).
    ended_stalls: Duration,
    /// A stall longer than [`LINK_STALL_LIMIT`] that ended before it was noticed (the first).
    overlong_stall: Option<Duration>,
    /// Packets heard from the described nodes so far.
    heard_count: u64,
    /// Since when unanswered exchanges have been excused as the link's stall (see
    /// [`Session::silence_counts`]); `None` while the link works.
    stalled_since: Option<Instant>,
}

/// The longest a wait sleeps between checks of its condition when no heartbeat or poll is
/// due sooner.
const CHECK_PERIOD: Duration = Duration::from_millis(10);

impl<T: Transport> Session<T> {
    /// A session with `form`'s nodes over `transport`; nothing is sent yet. Once the link is
    /// e-stopped (see [`Gate`](super::transport::Gate)) the session fails with
    /// [`SessionError::Stopped`].
    pub fn new(transport: T, form: &FormDescription) -> Self {
        let nodes = form.node_ids().map(|n| (n, NodeStatus::default())).collect();
        let stopped = transport.gate().watch();
        Self {
            transport,
            form: form.clone(),
            nodes,
            unexpected: Vec::new(),
            next_service: Instant::now(),
            next_heartbeat: Instant::now(),
            watch_liveness: false,
            stopped,
            clock: ListeningClock::new(),
            heard_any: Duration::ZERO,
            ended_stalls: Duration::ZERO,
            overlong_stall: None,
            heard_count: 0,
            stalled_since: None,
        }
    }

    /// How messages name `node`: its address and label.
    pub fn node_name(&self, node: NodeId) -> NodeName {
        let label =
            self.form.nodes.iter().find(|n| n.address == node.get()).and_then(|n| n.label.clone());
        NodeName { address: node.get(), label }
    }

    /// The form description.
    pub fn form(&self) -> &FormDescription {
        &self.form
    }

    /// The link's device name (`/dev/ttyUSB0`, `can0`, `simulated bus`).
    pub fn device(&self) -> String {
        self.transport.device()
    }

    /// The link's kind.
    pub fn link(&self) -> Link {
        self.transport.link()
    }

    /// What is known about every node of the description.
    pub fn nodes(&self) -> &BTreeMap<NodeId, NodeStatus> {
        &self.nodes
    }

    /// Mutable node status (to take events, clear the reboot mark).
    pub fn node_mut(&mut self, node: NodeId) -> Option<&mut NodeStatus> {
        self.nodes.get_mut(&node)
    }

    /// Addresses heard from that the description lacks.
    pub fn unexpected(&self) -> &[u8] {
        &self.unexpected
    }

    /// Sends one packet (refused once the link is e-stopped).
    pub async fn send(&mut self, packet: Packet) -> Result<(), SessionError> {
        match self.transport.send(packet).await {
            Err(TransportError::Stopped { cause, .. }) => Err(SessionError::Stopped(cause)),
            result => Ok(result?),
        }
    }

    fn handle(&mut self, packet: Packet) {
        let Address::Node(node) = packet.address else { return };
        if packet.message.code().direction() != firmware_protocol::message::Direction::NodeToHost {
            return;
        }
        if !self.nodes.contains_key(&node) {
            if !self.unexpected.contains(&node.get()) {
                self.unexpected.push(node.get());
            }
            return;
        }
        let now = self.clock.tick();
        self.link_heard(now);
        let excused = self.ended_stalls;
        let Some(status) = self.nodes.get_mut(&node) else { return };
        status.heard = Some(now);
        status.excused_at = excused;
        status.unanswered_polls = 0;
        match packet.message {
            Message::Heartbeat(h) => {
                // Back to Disabled without being told (only Disable does that), or homes
                // forgotten: the controller restarted.
                let was_on = status.heartbeat.is_some_and(|old| {
                    matches!(old.state, DriveState::Enabled | DriveState::Homing)
                });
                let forgot_homes =
                    status.heartbeat.is_some_and(|old| !old.homed.is_empty()) && h.homed.is_empty();
                if h.state == DriveState::Disabled && (was_on || forgot_homes) {
                    status.rebooted = true;
                }
                status.heartbeat = Some(h);
                status.heartbeat_at = Some(Instant::now());
            }
            Message::Feedback(four) => {
                let mut all = Positions8 { positions: status.positions };
                all.set_half(&four);
                status.positions = all.positions;
            }
            Message::AllFeedback(all) => status.positions = all.positions,
            Message::Force(four) => {
                let first = four.half.first();
                for (k, force) in four.forces.iter().enumerate() {
                    status.forces[first + k] = *force;
                    status.force_sums[first + k].add(*force);
                }
            }
            Message::AllForce(all) => {
                for (k, force) in all.forces.iter().enumerate() {
                    status.forces[k] = *force;
                    status.force_sums[k].add(*force);
                }
            }
            Message::Emergency(e) => status.events.push(e),
            Message::Identity(i) => status.identity = Some(i),
            Message::Capabilities(c) => status.capabilities = Some(c),
            _ => {}
        }
    }

    /// Fails once the link was e-stopped.
    fn check_stopped(&self) -> Result<(), SessionError> {
        match *self.stopped.borrow() {
            Some(cause) => Err(SessionError::Stopped(cause)),
            None => Ok(()),
        }
    }

    /// Receives and handles packets until `done` holds for one (returned) or `deadline`.
    /// Packets already received are taken before the deadline is honoured, so silence is
    /// never judged on a backlog.
    pub(super) async fn receive_until(
        &mut self,
        deadline: Instant,
        mut done: impl FnMut(&Packet) -> bool,
    ) -> Result<Option<Packet>, SessionError> {
        let mut stopped = self.stopped.clone();
        loop {
            self.check_stopped()?;
            self.keep_alive().await?;
            let wake = deadline.min(self.next_heartbeat);
            tokio::select! {
                biased;
                // A closed watch cannot change again: nothing to wait for there.
                Ok(()) = stopped.changed() => {}
                packet = self.transport.recv() => {
                    let packet = packet?;
                    self.handle(packet);
                    if done(&packet) {
                        return Ok(Some(packet));
                    }
                }
                () = sleep_until(wake) => {
                    self.clock.tick();
                    if Instant::now() >= deadline {
                        return Ok(None);
                    }
                }
            }
        }
    }

    /// Keeps the session alive (heartbeats, polls, receiving) until `done` holds for it or
    /// `deadline`; returns whether `done` held. Fails when a node is lost (once liveness is
    /// watched, after discovery).
    pub async fn wait_until(
        &mut self,
        deadline: Instant,
        mut done: impl FnMut(&Self) -> bool,
    ) -> Result<bool, SessionError> {
        loop {
            self.service().await?;
            if self.watch_liveness
                && let Some(lost) = self.lost()
            {
                return Err(lost);
            }
            if done(self) {
                return Ok(true);
            }
            if Instant::now() >= deadline {
                return Ok(false);
            }
            // Wake for the next heartbeat or poll, or at least every check period.
            let wake = deadline.min(self.next_service).min(Instant::now() + CHECK_PERIOD);
            self.receive_until(wake, |_| false).await?;
        }
    }

    /// Waits for a heartbeat from every node sent after now (on serial, nodes speak only when
    /// polled, so what is known may be from before): up to [`NODE_LOST_AFTER`] on CAN, and on
    /// serial up to one poll of every node with every answer late.
    pub async fn refresh(&mut self) -> Result<(), SessionError> {
        let since = Instant::now();
        self.next_service = since;
        let patience = match self.link() {
            Link::Serial => answer_timeout(Link::Serial) * self.nodes.len() as u32,
            _ => NODE_LOST_AFTER,
        };
        let fresh = |s: &Self| s.nodes.values().all(|n| n.heartbeat_at.is_some_and(|t| t > since));
        self.wait_until(since + patience.max(NODE_LOST_AFTER), fresh).await?;
        Ok(())
    }

    /// Takes the transport back.
    pub fn into_transport(self) -> T {
        self.transport
    }
}
