//! A session with the form's nodes: discovery against the form description, enabling,
//! homing, liveness both ways, and what every node last said.
//!
//! Packet handling:
//! * every received packet updates its node's [`NodeStatus`] (heartbeat, positions,
//!   identity, events); packets from addresses the description lacks are recorded as
//!   unexpected nodes;
//! * host heartbeats: on CAN a broadcast `HostHeartbeat` every 100 ms; on serial, where nodes
//!   speak only when polled, an addressed `HostHeartbeat` to every node in turn every 20 ms
//!   (the poll is the heartbeat);
//!   and, on every link, a broadcast `HostHeartbeat` whenever one is due while the session
//!   waits for an answer (so a long series of requests never starves a node's watchdog);
//! * requests (`IdentifyRequest`, `Control`, `Home`) are addressed and sent up to
//!   [`ATTEMPTS`] times on no answer; an `Ack` other than Ok is an error naming the node;
//! * an unanswered request or poll round tells nothing about the nodes when the link itself
//!   stalled meanwhile — the host's own write slept in the kernel longer than an answer may
//!   take, or the whole link carried nothing (on serial a poll of another node goes with
//!   every request, so that a working link always carries something): such an exchange
//!   does not count, for up to [`LINK_STALL_LIMIT`] in a row ([`Session::silence_counts`]);
//! * a node that misses three heartbeats in a row is lost. On CAN, where nodes send them
//!   unasked, that is [`NODE_LOST_AFTER`] of *listening time*: silence counts only while the
//!   host's receive loop actually runs ([`ListeningClock`]), so a host descheduled by a busy
//!   machine does not blame healthy nodes for its own stall. On serial, where the poll is the
//!   heartbeat, it is [`POLLS_LOST`] polls in a row unanswered: a host that polls slowly (busy,
//!   or behind a slow adapter) does not make a node that answers every poll silent. Received
//!   packets are always taken before silence is judged;
//! * a node's silence is told from the link's: every time the whole link carried nothing for
//!   more than [`LINK_QUIET`] (on CAN every node speaks every 20 ms) is the link's stall, and
//!   the session remembers them, so a node's silence leaves out every stall after its last
//!   packet — also once the link talks again, whichever node is heard first (the session used
//!   to excuse only a stall still going on, and after a stall of 0.5 s the first node heard
//!   made the others lost). A stall longer than [`LINK_STALL_LIMIT`] is an error of its own,
//!   [`SessionError::LinkStalled`], on every link: the adapter, cable or bus stopped, not a
//!   node. One node quiet while the others talk is lost after [`NODE_LOST_AFTER`], as ever;
//! * a node whose heartbeat falls back to Disabled unasked (or forgets its homes) has
//!   rebooted.
//!
//! **Faults** are found one way during homing and during a move ([`Session::fault`]): an
//! `Emergency` event with a fault code, or a heartbeat in Fault; the session halts every
//! node, then disables each ([`Session::stop_for_fault`]: none stays Enabled to latch a host
//! timeout once the host is gone), and reports the node and actuator in words. Latched
//! faults found at the start are cleared by [`Session::reset_faults`] only within what the
//! caller allows (see [`super::faults`]).
//!
//! Safety: the session never sends targets itself; `motion` builds them from
//! [`SafeTarget`](crate::form::safety::SafeTarget)s only. Every packet goes through the link's
//! [`Gate`](super::transport::Gate): once the link is e-stopped, from any thread, nothing else is
//! sent and the session ends with [`SessionError::Stopped`]. Every way out of a failed move
//! goes through a broadcast `Halt` or `EmergencyStop`.

use std::collections::BTreeMap;
use std::time::Duration;

use firmware_protocol::actuator::MAX_ACTUATORS;
use firmware_protocol::drive::{AckStatus, DriveCommand, DriveState, EmergencyCode, Faults};
use firmware_protocol::message::{
    Capabilities, Emergency, Heartbeat, HostHeartbeat, Identity, Positions8,
};
use firmware_protocol::version::Compatibility;
use firmware_protocol::{
    ActuatorSet, Address, Link, Message, NodeId, PROTOCOL_VERSION, Packet, Position, timing,
};
use form_description::FormDescription;
use tokio::sync::watch;
use tokio::time::{Instant, sleep_until};

use super::faults::{self, Fault, NodeName};
use super::transport::{StopCause, Transport, TransportError};

/// The host heartbeat period on CAN.
pub const HEARTBEAT_PERIOD: Duration =
    Duration::from_millis(timing::HOST_HEARTBEAT_PERIOD_MS as u64);
/// The poll period on serial.
pub const POLL_PERIOD: Duration = Duration::from_millis(timing::FEEDBACK_PERIOD_MS as u64);
/// A node not heard for this long is lost (three heartbeat periods).
pub const NODE_LOST_AFTER: Duration = Duration::from_millis(timing::NODE_LOST_AFTER_MS as u64);
/// A serial node that leaves this many polls in a row unanswered is lost: the poll is its
/// heartbeat, and [`NODE_LOST_AFTER`] is this many heartbeat periods.
pub const POLLS_LOST: u32 = (timing::NODE_LOST_AFTER_MS / timing::HEARTBEAT_PERIOD_MS) as u32;
/// How long the whole link may carry nothing before its silence is blamed on the nodes (CAN)
/// or requests time out regardless: the longest stall of a pseudo-terminal measured on a
/// loaded 2-core machine (1.3 s, the kernel holding every pty's bytes; see the simulator's `bus/pty.rs`),
/// with margin. A single silent node is still found within [`NODE_LOST_AFTER`], since the
/// others keep talking.
pub const LINK_STALL_LIMIT: Duration = Duration::from_secs(2);
/// On CAN, the link carrying nothing at all for longer than this (two feedback periods of
/// every node) is the link's stall, not the nodes' silence.
const LINK_QUIET: Duration = Duration::from_millis(2 * timing::FEEDBACK_PERIOD_MS as u64);
/// The longest a gap between two wakes of the receive loop counts towards a node's silence:
/// the loop wakes at least every answer timeout (60 ms on serial), so a longer gap is the
/// host's own stall (one heartbeat period allows for a busy machine).
pub const LONGEST_COUNTED_GAP: Duration = HEARTBEAT_PERIOD;
/// How long to wait for the `Emergency` event of a node seen in Fault (on serial it comes
/// after the heartbeat, in the same poll answer; two poll periods leave room).
const EVENT_GRACE: Duration = Duration::from_millis(2 * timing::FEEDBACK_PERIOD_MS as u64);

/// Time in which the host was listening: wall time, except that a gap between two wakes of
/// the receive loop longer than [`LONGEST_COUNTED_GAP`] (the process was descheduled) counts
/// only that much.
#[derive(Clone, Copy, Debug)]
pub struct ListeningClock {
    listened: Duration,
    last: Instant,
}

impl ListeningClock {
    fn new() -> Self {
        Self { listened: Duration::ZERO, last: Instant::now() }
    }

    /// Counts the time since the last tick; returns the listening time now.
    fn tick(&mut self) -> Duration {
        let now = Instant::now();
        self.listened += now.saturating_duration_since(self.last).min(LONGEST_COUNTED_GAP);
        self.last = now;
        self.listened
    }
}

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

/// A problem found when checking the nodes against the form description.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum NodeProblem {
    /// A node of the description did not answer.
    #[error("node {0}: missing (no answer to IdentifyRequest)")]
    Missing(u8),
    /// A node answered that the description lacks.
    #[error("node {0}: unexpected (not in the form description)")]
    Unexpected(u8),
    /// Another major protocol version.
    #[error("node {node}: protocol {found}, the host speaks {host} (another major version)")]
    Version {
        /// The node.
        node: u8,
        /// Its version.
        found: String,
        /// The host's.
        host: String,
    },
    /// Its actuators differ from the description.
    #[error("node {node}: {what}: the node reports {found}, the form description says {expected}")]
    Mismatch {
        /// The node.
        node: u8,
        /// Which quantity.
        what: &'static str,
        /// What the node reports.
        found: String,
        /// What the description says.
        expected: String,
    },
}

/// Why a session failed.
#[derive(Debug, thiserror::Error)]
pub enum SessionError {
    /// The link failed.
    #[error(transparent)]
    Transport(#[from] TransportError),
    /// The nodes do not match the description.
    #[error("the form does not match its description:\n  {}", list(.0))]
    Discovery(Vec<NodeProblem>),
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
    /// [`super::claim`]): the command ends without clearing it.
    #[error("stopped by an e-stop latched on node(s) {} after this command started (not cleared: check the form, then `dressform reset`)", crate::messages::list(.0))]
    StoppedSinceStart(Vec<u8>),
    /// The link was e-stopped (another terminal, a signal): the session sent nothing more.
    #[error("stopped by {0}: emergency stop sent to every node")]
    Stopped(StopCause),
}

/// A node's latched faults, as found and after a FaultReset.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Cleared {
    /// The node.
    pub node: NodeName,
    /// Its faults before the reset.
    pub faults: Faults,
    /// The actuators its fault events named.
    pub actuators: Vec<String>,
    /// What the reset left latched (empty: cleared).
    pub remaining: Faults,
}

impl std::fmt::Display for Cleared {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}", self.node)?;
        if !self.actuators.is_empty() {
            write!(f, ", {}", self.actuators.join(", "))?;
        }
        write!(f, ": {}", faults::describe(self.faults))
    }
}

fn list(problems: &[NodeProblem]) -> String {
    let lines: Vec<String> = problems.iter().map(ToString::to_string).collect();
    lines.join("\n  ")
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

/// How many times a request is sent before its node is reported: the protocol's two
/// retries ([`timing::RETRIES`]), plus two more so that a lossy bus (5 % of frames lost each
/// way) does not fail a whole session on one node's bad luck.
pub const ATTEMPTS: u8 = timing::RETRIES + 3;

/// How many times a node that reboots while the host waits for it to be ready is enabled
/// again.
const REENABLES: usize = 2;

/// A request's name for people: a drive command's own name (`Enable`), else its code's.
fn request_name(request: &Message) -> &'static str {
    match request {
        Message::Control(DriveCommand::Disable) => "Disable",
        Message::Control(DriveCommand::Enable) => "Enable",
        Message::Control(DriveCommand::FaultReset) => "FaultReset",
        Message::Control(DriveCommand::Halt) => "Halt",
        other => other.code().name(),
    }
}

/// How long to wait for an answer on a serial link before retrying: a pseudo-terminal or a
/// USB adapter on a busy host answers in a few ms, plus the node's poll cycle; lenient.
const SERIAL_ANSWER_TIMEOUT: Duration = Duration::from_millis(60);
/// The same on CAN, where a node answers as soon as the frame arrives (1 Mbit/s: a frame
/// takes about 0.13 ms); lenient for a busy host.
const CAN_ANSWER_TIMEOUT: Duration = Duration::from_millis(30);
/// The longest a wait sleeps between checks of its condition when no heartbeat or poll is
/// due sooner.
const CHECK_PERIOD: Duration = Duration::from_millis(10);

/// How much of a whole-link silence of `quiet` was the link's stall: all of it once longer
/// than [`LINK_QUIET`], up to [`LINK_STALL_LIMIT`] (beyond that the link is reported stalled).
fn stall_part(quiet: Duration) -> Duration {
    if quiet > LINK_QUIET { quiet.min(LINK_STALL_LIMIT) } else { Duration::ZERO }
}

/// How long to wait for an answer before retrying.
fn answer_timeout(link: Link) -> Duration {
    match link {
        Link::Serial => SERIAL_ANSWER_TIMEOUT,
        _ => CAN_ANSWER_TIMEOUT,
    }
}

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

    /// Broadcasts `Halt`: every node stops its moves and homing, and stays Enabled.
    pub async fn halt_all(&mut self) -> Result<(), SessionError> {
        self.send(Packet::broadcast(Message::Control(DriveCommand::Halt))).await
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
            Message::Emergency(e) => status.events.push(e),
            Message::Identity(i) => status.identity = Some(i),
            Message::Capabilities(c) => status.capabilities = Some(c),
            _ => {}
        }
    }

    /// The link carried a packet from a described node at listening time `now`: the
    /// whole-link silence it ends, if longer than [`LINK_QUIET`], was the link's stall (see
    /// [`Session::excused`]); one longer than [`LINK_STALL_LIMIT`] is kept for
    /// [`Session::lost`] to report.
    fn link_heard(&mut self, now: Duration) {
        if self.heard_count > 0 {
            let quiet = now.saturating_sub(self.heard_any);
            self.ended_stalls += stall_part(quiet);
            if quiet > LINK_STALL_LIMIT {
                self.overlong_stall.get_or_insert(quiet);
            }
        }
        self.heard_any = now;
        self.heard_count += 1;
    }

    /// How long the whole link has carried nothing from any node at listening time `now`
    /// (zero before it carried anything).
    fn link_quiet(&self, now: Duration) -> Duration {
        if self.heard_count == 0 { Duration::ZERO } else { now.saturating_sub(self.heard_any) }
    }

    /// The link's stalls up to listening time `now`, the one going on included: the time the
    /// whole link carried nothing for longer than [`LINK_QUIET`], each stall counted up to
    /// [`LINK_STALL_LIMIT`]. A node's silence leaves out what this grew by since it was last
    /// heard ([`NodeStatus::excused_at`]), whichever node the link carried first afterwards.
    fn excused(&self, now: Duration) -> Duration {
        self.ended_stalls + stall_part(self.link_quiet(now))
    }

    /// Fails once the link was e-stopped.
    fn check_stopped(&self) -> Result<(), SessionError> {
        match *self.stopped.borrow() {
            Some(cause) => Err(SessionError::Stopped(cause)),
            None => Ok(()),
        }
    }

    /// A broadcast host heartbeat when one is due (on serial, between polls too).
    async fn keep_alive(&mut self) -> Result<(), SessionError> {
        let now = Instant::now();
        if now >= self.next_heartbeat {
            self.next_heartbeat = now + HEARTBEAT_PERIOD;
            let heartbeat = Message::HostHeartbeat(HostHeartbeat { protocol: PROTOCOL_VERSION });
            self.send(Packet::broadcast(heartbeat)).await?;
        }
        Ok(())
    }

    /// Receives and handles packets until `done` holds for one (returned) or `deadline`.
    /// Packets already received are taken before the deadline is honoured, so silence is
    /// never judged on a backlog.
    async fn receive_until(
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

    /// Whether an exchange that went unanswered counts against the nodes, given the packets
    /// heard before it began and how long the host's write of it took. It does not while the
    /// link is stalled (the write slept in the kernel longer than an answer may take, or
    /// nothing at all was heard meanwhile: on a loaded machine the tty layer can hold every
    /// pty's bytes for a second, see the simulator's `bus/pty.rs`), for up to [`LINK_STALL_LIMIT`] in a
    /// row: a dead link, or a host whose every write sleeps, is still reported.
    fn silence_counts(&mut self, heard_before: u64, wrote_for: Duration) -> bool {
        let stalled = wrote_for > answer_timeout(self.link()) || self.heard_count == heard_before;
        if !stalled {
            self.stalled_since = None;
            return true;
        }
        let now = Instant::now();
        let since = *self.stalled_since.get_or_insert(now);
        now.saturating_duration_since(since) > LINK_STALL_LIMIT
    }

    /// Sends `packet` and returns how long the write took (it can sleep in the kernel).
    async fn timed_send(&mut self, packet: Packet) -> Result<Duration, SessionError> {
        let start = Instant::now();
        self.send(packet).await?;
        Ok(start.elapsed())
    }

    /// On serial, where nodes speak only when asked, polls a node other than `node` (the one
    /// heard last): its answer shows whether the link carried anything while `node` was
    /// asked something (see [`Session::silence_counts`]). On CAN the nodes speak unasked.
    async fn poll_witness(&mut self, node: NodeId) -> Result<(), SessionError> {
        if self.link() != Link::Serial {
            return Ok(());
        }
        let witness = self.nodes.iter().filter(|(n, _)| **n != node).max_by_key(|(_, s)| s.heard);
        if let Some((&witness, _)) = witness {
            let heartbeat = Message::HostHeartbeat(HostHeartbeat { protocol: PROTOCOL_VERSION });
            self.send(Packet::node(witness, heartbeat)).await?;
        }
        Ok(())
    }

    /// Sends `packet` (addressed to `node`) until its node has sent every answer the code
    /// table names for it ([`Code::answers`]), or an `Ack` naming it; up to
    /// [`ATTEMPTS`] times (attempts while the link stalls do not count). Returns the last
    /// answer.
    async fn request(&mut self, packet: Packet) -> Result<Message, SessionError> {
        let node = match packet.address {
            Address::Node(n) => n,
            Address::Broadcast => NodeId::MIN,
        };
        let request = packet.message;
        // What is still awaited; an answer heard in an earlier attempt counts.
        let mut awaited = request.code().answers().to_vec();
        let attempts = ATTEMPTS;
        let mut made = 0;
        while made < attempts {
            let heard = self.heard_count;
            let wrote_for = self.timed_send(packet).await?;
            self.poll_witness(node).await?;
            let deadline = Instant::now() + answer_timeout(self.link());
            let answer = self
                .receive_until(deadline, |p| {
                    if p.address != Address::Node(node) || !p.message.answers(&request) {
                        return false;
                    }
                    awaited.retain(|&code| code != p.message.code());
                    awaited.is_empty() || matches!(p.message, Message::Ack(_))
                })
                .await?;
            if let Some(answer) = answer {
                self.stalled_since = None;
                return Ok(answer.message);
            }
            if self.silence_counts(heard, wrote_for) {
                made += 1;
            }
        }
        Err(SessionError::NoAnswer { node: node.get(), request: request_name(&request), attempts })
    }

    /// Host heartbeats (CAN) or polls (serial) when due.
    async fn service(&mut self) -> Result<(), SessionError> {
        let now = Instant::now();
        if now < self.next_service {
            return Ok(());
        }
        if self.link() == Link::Serial {
            self.next_service = now + POLL_PERIOD;
            let heartbeat = Message::HostHeartbeat(HostHeartbeat { protocol: PROTOCOL_VERSION });
            let nodes: Vec<NodeId> = self.nodes.keys().copied().collect();
            let heard = self.heard_count;
            let mut slowest_write = Duration::ZERO;
            let mut unanswered = Vec::new();
            for node in nodes {
                // A lost poll is noticed by liveness, not retried.
                let deadline = Instant::now() + answer_timeout(Link::Serial);
                slowest_write =
                    slowest_write.max(self.timed_send(Packet::node(node, heartbeat)).await?);
                let answer = self
                    .receive_until(deadline, |p| {
                        p.address == Address::Node(node)
                            && matches!(p.message, Message::AllFeedback(_))
                    })
                    .await?;
                if answer.is_none() {
                    unanswered.push(node);
                }
            }
            // A round in which the link stalled tells nothing about the nodes.
            if !unanswered.is_empty() && self.silence_counts(heard, slowest_write) {
                for node in unanswered {
                    if let Some(status) = self.nodes.get_mut(&node) {
                        // Any packet from the node starts the count again (see `handle`).
                        status.unanswered_polls += 1;
                    }
                }
            }
        } else {
            self.next_service = now + HEARTBEAT_PERIOD;
            self.next_heartbeat = now;
            self.keep_alive().await?;
        }
        Ok(())
    }

    /// The link stalled, or the first node lost (see the module docs): on every link, nothing
    /// heard from any node for longer than [`LINK_STALL_LIMIT`] (going on, or ended since the
    /// last look) is the link's stall; on serial, a node that left [`POLLS_LOST`] polls in a
    /// row unanswered is lost; on CAN, one not heard for [`NODE_LOST_AFTER`] of listening time,
    /// the link's stalls since its last packet left out ([`Session::excused`]: on CAN every
    /// node speaks every 20 ms, so the whole link quiet is the link's stall — a busy host's tty
    /// layer holding every byte, a stopped adapter — while one node quiet among talking ones
    /// is that node's silence).
    fn lost(&mut self) -> Option<SessionError> {
        let now = self.clock.tick();
        let quiet = self.link_quiet(now);
        let overlong = (quiet > LINK_STALL_LIMIT).then_some(quiet);
        if let Some(quiet) = self.overlong_stall.or(overlong) {
            return Some(SessionError::LinkStalled { quiet });
        }
        let serial = self.link() == Link::Serial;
        let excused = self.excused(now);
        self.nodes.iter().find_map(|(&node, status)| {
            let stalled = excused.saturating_sub(status.excused_at);
            let silent = now.saturating_sub(status.heard?).saturating_sub(stalled);
            let node = node.get();
            if serial {
                (status.unanswered_polls >= POLLS_LOST)
                    .then_some(SessionError::NodeUnanswered { node, silent })
            } else {
                (silent > NODE_LOST_AFTER).then_some(SessionError::NodeLost { node, silent })
            }
        })
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

    /// Identifies `node` (Identity, then Capabilities) and checks it against the description.
    pub async fn identify(&mut self, node: NodeId) -> Result<Vec<NodeProblem>, SessionError> {
        if let Some(status) = self.nodes.get_mut(&node) {
            status.identity = None;
            status.capabilities = None;
        }
        // Both answers (Identity, then Capabilities), asking again until both are in.
        match self.request(Packet::node(node, Message::IdentifyRequest)).await {
            Ok(_) => {}
            Err(SessionError::NoAnswer { .. }) => {
                return Ok(vec![NodeProblem::Missing(node.get())]);
            }
            Err(e) => return Err(e),
        }
        let status = self.nodes.get(&node).cloned().unwrap_or_default();
        let now = self.clock.tick();
        let excused = self.excused(now);
        if let Some(status) = self.nodes.get_mut(&node) {
            status.heard = Some(now);
            status.excused_at = excused;
        }
        Ok(self.check(node, &status))
    }

    fn check(&self, node: NodeId, status: &NodeStatus) -> Vec<NodeProblem> {
        let (Some(identity), Some(caps)) = (status.identity, status.capabilities) else {
            return vec![NodeProblem::Missing(node.get())];
        };
        let n = node.get();
        if PROTOCOL_VERSION.compatibility(identity.protocol) == Compatibility::Incompatible {
            return vec![NodeProblem::Version {
                node: n,
                found: format!("{}.{}", identity.protocol.major, identity.protocol.minor),
                host: format!("{}.{}", PROTOCOL_VERSION.major, PROTOCOL_VERSION.minor),
            }];
        }
        let actuators = self.form.actuators_of(node);
        let mut problems = Vec::new();
        let mut mismatch = |what, found: String, expected: String| {
            if found != expected {
                problems.push(NodeProblem::Mismatch { node: n, what, found, expected });
            }
        };
        mismatch(
            "actuator count",
            identity.actuator_count.to_string(),
            actuators.len().to_string(),
        );
        // A node reports the weakest of its actuators.
        let stroke = actuators.iter().map(|a| a.stroke()).min().unwrap_or_default();
        mismatch("stroke", format!("{} mm", caps.stroke.mm()), format!("{} mm", stroke.mm()));
        let speed = actuators.iter().map(|a| a.max_speed()).min().unwrap_or_default();
        mismatch(
            "max speed",
            format!("{} mm/s", caps.max_speed.mm_s()),
            format!("{} mm/s", speed.mm_s()),
        );
        let accel = actuators.iter().map(|a| a.max_accel()).min().unwrap_or_default();
        mismatch(
            "max acceleration",
            format!("{} mm/s²", caps.max_accel.mm_s2()),
            format!("{} mm/s²", accel.mm_s2()),
        );
        problems
    }

    /// Identifies every node of the description and checks it: protocol major version,
    /// actuator count, stroke and limits. On CAN a broadcast `IdentifyRequest` also finds
    /// nodes the description lacks. Then watches every node's liveness.
    pub async fn discover(&mut self) -> Result<(), SessionError> {
        let mut problems = Vec::new();
        let nodes: Vec<NodeId> = self.nodes.keys().copied().collect();
        for node in nodes {
            problems.extend(self.identify(node).await?);
        }
        if self.link() != Link::Serial {
            self.send(Packet::broadcast(Message::IdentifyRequest)).await?;
            let deadline = Instant::now() + answer_timeout(self.link());
            self.receive_until(deadline, |_| false).await?;
        }
        problems.extend(self.unexpected.iter().map(|&n| NodeProblem::Unexpected(n)));
        if !problems.is_empty() {
            return Err(SessionError::Discovery(problems));
        }
        self.watch_liveness = true;
        Ok(())
    }

    /// Sends a `Control` command to `node` and checks its `Ack`.
    pub async fn control(
        &mut self,
        node: NodeId,
        command: DriveCommand,
    ) -> Result<(), SessionError> {
        let message = Message::Control(command);
        let answer = self.request(Packet::node(node, message)).await?;
        self.expect_ok(node, request_name(&message), answer).await
    }

    /// Checks a request's `Ack`; a refusal names the node's state and faults as a fresh
    /// heartbeat shows them (the last one known may be from before the request: on serial,
    /// from the poll before it — a node that latched a fault meanwhile would be misreported
    /// as Disabled).
    async fn expect_ok(
        &mut self,
        node: NodeId,
        name: &'static str,
        answer: Message,
    ) -> Result<(), SessionError> {
        match answer {
            Message::Ack(ack) if ack.status == AckStatus::Ok => Ok(()),
            Message::Ack(ack) => {
                // Only an e-stop outranks the refusal; without a fresh heartbeat the hint
                // uses the last one.
                if let Err(stopped @ SessionError::Stopped(_)) = self.refresh().await {
                    return Err(stopped);
                }
                let hint = match self.nodes.get(&node).and_then(|s| s.heartbeat) {
                    Some(h) if !h.faults.is_empty() => format!(
                        " (node {}: {})",
                        faults::state_name(h.state),
                        faults::describe(h.faults)
                    ),
                    Some(h) => format!(" (node {})", faults::state_name(h.state)),
                    None => String::new(),
                };
                Err(SessionError::Refused {
                    node: node.get(),
                    request: name,
                    status: ack.status,
                    hint,
                })
            }
            _ => Err(SessionError::NoAnswer { node: node.get(), request: name, attempts: 1 }),
        }
    }

    /// The actuators of `node` in the description.
    pub fn actuator_set(&self, node: NodeId) -> ActuatorSet {
        self.form.actuators_of(node).iter().filter_map(|a| a.actuator()).collect()
    }

    /// Enables `node` and homes its actuators whose home is unknown (latched faults are
    /// [`Session::reset_faults`]'s). Does not wait for homing to finish.
    pub async fn enable(&mut self, node: NodeId) -> Result<(), SessionError> {
        // A recent host heartbeat first: nodes refuse Enable without one (InvalidState), so
        // after a lost heartbeat, another heartbeat and another try.
        let mut attempts = 1;
        loop {
            self.next_service = Instant::now();
            self.service().await?;
            match self.control(node, DriveCommand::Enable).await {
                Err(SessionError::Refused { status: AckStatus::InvalidState, .. })
                    if attempts < ATTEMPTS =>
                {
                    attempts += 1;
                }
                result => break result?,
            }
        }
        let wanted = self.actuator_set(node);
        let homed =
            self.nodes.get(&node).and_then(|s| s.heartbeat).map_or(ActuatorSet::EMPTY, |h| h.homed);
        let missing: ActuatorSet = wanted.iter().filter(|&a| !homed.contains(a)).collect();
        if !missing.is_empty() {
            let answer = self.request(Packet::node(node, Message::Home(missing))).await?;
            self.expect_ok(node, "Home", answer).await?;
            // The heartbeat that follows shows Homing; forget the old one meanwhile.
            if let Some(status) = self.nodes.get_mut(&node) {
                status.heartbeat =
                    status.heartbeat.map(|h| Heartbeat { state: DriveState::Homing, ..h });
            }
        }
        Ok(())
    }

    /// Whether every actuator of `node` is homed, its position reported, and the node
    /// Enabled.
    pub fn ready(&self, node: NodeId) -> bool {
        let wanted = self.actuator_set(node);
        self.nodes.get(&node).is_some_and(|s| {
            s.heartbeat.is_some_and(|h| {
                h.state == DriveState::Enabled && wanted.iter().all(|a| h.homed.contains(a))
            }) && wanted.iter().all(|a| s.positions[a.index()].is_some())
        })
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

    /// Clears the latched faults of every node within `allowed(node)`: refuses (sending nothing)
    /// when a node holds another fault ([`SessionError::Latched`], naming the node, the
    /// actuators its events named, and the faults in words); otherwise sends FaultReset to
    /// every node in Fault, after a fresh host heartbeat (the node checks the host is alive
    /// before clearing a host timeout). Returns, per node that was in Fault, what it held and
    /// what remains. Events from before are consumed.
    pub async fn reset_faults(
        &mut self,
        allowed: impl Fn(NodeId) -> Faults,
    ) -> Result<Vec<Cleared>, SessionError> {
        self.refresh().await?;
        // Events still pending on a node (serial keeps them for the next poll) are old news
        // by now: take them for the actuators they name.
        self.wait_until(Instant::now() + EVENT_GRACE, |_| false).await?;
        let mut found = Vec::new();
        for (&node, status) in &mut self.nodes {
            let events = std::mem::take(&mut status.events);
            let Some(h) = status.heartbeat.filter(|h| h.state == DriveState::Fault) else {
                continue;
            };
            let mut actuators: Vec<String> = events
                .iter()
                .filter(|e| !e.code.fault().is_empty())
                .filter_map(|e| self.form.actuator_at(node, e.actuator?).map(|a| a.id.clone()))
                .collect();
            actuators.dedup();
            found.push((node, h.faults, actuators));
        }
        let mut cleared: Vec<Cleared> = found
            .into_iter()
            .map(|(node, faults, actuators)| Cleared {
                node: self.node_name(node),
                faults,
                actuators,
                remaining: faults,
            })
            .collect();
        let refused: Vec<String> = cleared
            .iter()
            .filter(|c| NodeId::new(c.node.address).is_none_or(|n| !allowed(n).contains(c.faults)))
            .map(ToString::to_string)
            .collect();
        if !refused.is_empty() {
            return Err(SessionError::Latched(refused));
        }
        for c in &mut cleared {
            let Some(node) = NodeId::new(c.node.address) else { continue };
            self.next_heartbeat = Instant::now();
            self.keep_alive().await?;
            match self.control(node, DriveCommand::FaultReset).await {
                Ok(()) => c.remaining = Faults::empty(),
                Err(SessionError::Refused { .. }) => {}
                Err(e) => return Err(e),
            }
        }
        // The heartbeats after the resets show what remains.
        self.refresh().await?;
        for c in &mut cleared {
            let heartbeat = NodeId::new(c.node.address)
                .and_then(|n| self.nodes.get(&n))
                .and_then(|s| s.heartbeat);
            if let Some(h) = heartbeat {
                c.remaining = if h.state == DriveState::Fault { h.faults } else { Faults::empty() };
            }
        }
        for status in self.nodes.values_mut() {
            status.events.clear();
        }
        Ok(cleared)
    }

    /// The first fault among the nodes: an `Emergency` event with a fault code, or a node
    /// in Fault (for which its event is awaited a little, to name the actuator). Warnings
    /// found on the way go to `warnings`. Events are consumed.
    pub async fn fault(
        &mut self,
        warnings: &mut Vec<String>,
    ) -> Result<Option<Fault>, SessionError> {
        if let Some(fault) = self.take_fault_event(warnings) {
            return Ok(Some(fault));
        }
        let in_fault = |s: &Self| {
            s.nodes
                .iter()
                .find(|(_, st)| st.heartbeat.is_some_and(|h| h.state == DriveState::Fault))
                .map(|(&n, _)| n)
        };
        let Some(node) = in_fault(self) else { return Ok(None) };
        let has_event = |s: &Self| {
            s.nodes.values().any(|st| st.events.iter().any(|e| !e.code.fault().is_empty()))
        };
        self.wait_until(Instant::now() + EVENT_GRACE, has_event).await?;
        if let Some(fault) = self.take_fault_event(warnings) {
            return Ok(Some(fault));
        }
        let flags =
            self.nodes.get(&node).and_then(|s| s.heartbeat).map_or(Faults::empty(), |h| h.faults);
        Ok(Some(Fault {
            node: self.node_name(node),
            actuator: None,
            what: faults::describe(flags),
        }))
    }

    /// Stops the form after `fault` (during homing or a move): broadcasts `Halt`, so every
    /// node stops at once, then disables every node, each acknowledging (refusals ignored: the
    /// faulty node is in Fault), so that none stays Enabled to latch a host timeout once the
    /// host is gone. Returns the error to report: the fault, or what failed the link meanwhile
    /// (an e-stop, the link itself).
    pub async fn stop_for_fault(&mut self, fault: Fault) -> SessionError {
        match self.halt_all().await {
            Ok(()) => match self.disable_all().await {
                Ok(()) => SessionError::Fault(fault),
                Err(e) => e,
            },
            Err(e) => e,
        }
    }

    /// Consumes every node's events: the first fault is returned, warnings are kept.
    fn take_fault_event(&mut self, warnings: &mut Vec<String>) -> Option<Fault> {
        let mut found = None;
        let nodes: Vec<NodeId> = self.nodes.keys().copied().collect();
        for node in nodes {
            let Some(status) = self.nodes.get_mut(&node) else { continue };
            let events = std::mem::take(&mut status.events);
            let in_fault = status.heartbeat.is_some_and(|h| h.state == DriveState::Fault);
            for e in events {
                let actuator = e
                    .actuator
                    .and_then(|a| self.form.actuator_at(node, a).map(|spec| spec.id.clone()));
                // An unknown code is a fault if the node is in Fault (the README's rule).
                let is_fault = !e.code.fault().is_empty()
                    || (e.code != EmergencyCode::NO_ERROR
                        && in_fault
                        && EmergencyCode::KNOWN.iter().all(|(c, _)| *c != e.code));
                let what = faults::event_words(e.code, e.detail);
                if is_fault {
                    if found.is_none() {
                        found = Some(Fault { node: self.node_name(node), actuator, what });
                    }
                } else if e.code != EmergencyCode::NO_ERROR {
                    let target = actuator.unwrap_or_else(|| "the node".into());
                    warnings.push(format!("{}, {target}: {what}", self.node_name(node)));
                }
            }
        }
        found
    }

    /// Enables every node, homes what needs it, and waits until all are ready.
    pub async fn enable_all(&mut self, homing_timeout: Duration) -> Result<(), SessionError> {
        let nodes: Vec<NodeId> = self.nodes.keys().copied().collect();
        for &node in &nodes {
            self.enable(node).await?;
        }
        self.wait_ready(&nodes, homing_timeout).await
    }

    /// Waits until every node of `nodes` is Enabled and homed.
    pub async fn wait_ready(
        &mut self,
        nodes: &[NodeId],
        timeout: Duration,
    ) -> Result<(), SessionError> {
        let deadline = Instant::now() + timeout;
        let mut warnings = Vec::new();
        // A node that reboots meanwhile is identified and enabled again (a few times).
        for _ in 0..=REENABLES {
            let rebooted =
                |s: &Self| nodes.iter().any(|n| s.nodes.get(n).is_some_and(|s| s.rebooted));
            let faulted = |s: &Self| {
                s.nodes.values().any(|st| {
                    st.heartbeat.is_some_and(|h| h.state == DriveState::Fault)
                        || st.events.iter().any(|e| !e.code.fault().is_empty())
                })
            };
            let finished = self
                .wait_until(deadline, |s| {
                    nodes.iter().all(|&n| s.ready(n)) || rebooted(s) || faulted(s)
                })
                .await?;
            // A fault during homing: reported at once, as during a move.
            if let Some(fault) = self.fault(&mut warnings).await? {
                return Err(self.stop_for_fault(fault).await);
            }
            if finished && !rebooted(self) {
                return Ok(());
            }
            let again: Vec<NodeId> = nodes
                .iter()
                .copied()
                .filter(|n| self.nodes.get(n).is_some_and(|s| s.rebooted))
                .collect();
            if again.is_empty() {
                break;
            }
            for node in again {
                if let Some(status) = self.nodes.get_mut(&node) {
                    status.rebooted = false;
                }
                let problems = self.identify(node).await?;
                if !problems.is_empty() {
                    return Err(SessionError::Discovery(problems));
                }
                self.enable(node).await?;
            }
        }
        let pending = nodes
            .iter()
            .filter(|&&n| !self.ready(n))
            .map(|&n| {
                let state = match self.nodes.get(&n).and_then(|s| s.heartbeat) {
                    Some(h) => faults::state_name(h.state),
                    None => "no heartbeat",
                };
                format!("{} ({state})", self.node_name(n))
            })
            .collect();
        Err(SessionError::Homing { timeout, nodes: pending })
    }

    /// Disables every node (panels hold: the drives are self-locking), ignoring refusals.
    pub async fn disable_all(&mut self) -> Result<(), SessionError> {
        let nodes: Vec<NodeId> = self.nodes.keys().copied().collect();
        for node in nodes {
            match self.control(node, DriveCommand::Disable).await {
                Ok(()) | Err(SessionError::Refused { .. } | SessionError::NoAnswer { .. }) => {}
                Err(e) => return Err(e),
            }
        }
        Ok(())
    }

    /// Takes the transport back.
    pub fn into_transport(self) -> T {
        self.transport
    }
}
