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
//! * requests (`IdentifyRequest`, `Control`, `Home`) are addressed and sent up to
//!   [`ATTEMPTS`] times on no answer; an `Ack` other than Ok is an error naming the node;
//! * a node not heard for [`timing::NODE_LOST_AFTER_MS`] (three heartbeat periods) is lost;
//! * a node whose heartbeat falls back to Disabled unasked (or forgets its homes) has
//!   rebooted.
//!
//! Safety: the session never sends targets itself; `motion` builds them from
//! [`SafeTarget`](super::safety::SafeTarget)s only. Every way out of a failed move goes
//! through a broadcast `Halt` or `EmergencyStop`.

use std::collections::BTreeMap;
use std::time::Duration;

use firmware_protocol::actuator::MAX_ACTUATORS;
use firmware_protocol::drive::{AckStatus, DriveCommand, DriveState};
use firmware_protocol::message::{Capabilities, Emergency, Heartbeat, HostHeartbeat, Identity};
use firmware_protocol::version::Compatibility;
use firmware_protocol::{
    ActuatorSet, Address, Code, Link, Message, NodeId, PROTOCOL_VERSION, Packet, Position, timing,
};
use sim::form::FormDescription;
use tokio::sync::watch;
use tokio::time::{Instant, sleep_until};

use super::transport::{Transport, TransportError};

/// The host heartbeat period on CAN.
pub const HEARTBEAT_PERIOD: Duration =
    Duration::from_millis(timing::HOST_HEARTBEAT_PERIOD_MS as u64);
/// The poll period on serial.
pub const POLL_PERIOD: Duration = Duration::from_millis(timing::FEEDBACK_PERIOD_MS as u64);
/// A node not heard for this long is lost (three heartbeat periods).
pub const NODE_LOST_AFTER: Duration = Duration::from_millis(timing::NODE_LOST_AFTER_MS as u64);

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
    /// When it was last heard from.
    pub last_heard: Option<Instant>,
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
    #[error("node {node}: {request} refused: {status:?}{hint}")]
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
    /// A node went silent.
    #[error("node {node}: lost: nothing heard for {} ms (limit {} ms)", silent.as_millis(), NODE_LOST_AFTER.as_millis())]
    NodeLost {
        /// The node.
        node: u8,
        /// How long it had been silent when noticed.
        silent: Duration,
    },
    /// Homing did not finish in time.
    #[error("homing did not finish within {} s: {}", .timeout.as_secs(), .nodes.join(", "))]
    Homing {
        /// How long the host waited.
        timeout: Duration,
        /// The nodes still homing, with their state.
        nodes: Vec<String>,
    },
    /// The user stopped the session (Ctrl-C): an emergency stop was sent.
    #[error("interrupted: emergency stop sent to every node")]
    Interrupted,
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
    watch_liveness: bool,
    stop: Option<watch::Receiver<bool>>,
}

/// How many times a request is sent before its node is reported: the protocol's two
/// retries ([`timing::RETRIES`]), plus two more so that a lossy bus (5 % of frames lost each
/// way) does not fail a whole session on one node's bad luck.
pub const ATTEMPTS: u8 = timing::RETRIES + 3;

/// How many times a node that reboots while the host waits for it to be ready is enabled
/// again.
const REENABLES: usize = 2;

/// How long to wait for an answer before retrying.
fn answer_timeout(link: Link) -> Duration {
    match link {
        // A pseudo-terminal or USB adapter on a busy host answers in a few ms; be lenient.
        Link::Serial => Duration::from_millis(60),
        _ => Duration::from_millis(30),
    }
}

impl<T: Transport> Session<T> {
    /// A session with `form`'s nodes over `transport`; nothing is sent yet. A `stop` that
    /// turns true makes the session send an emergency stop and fail with
    /// [`SessionError::Interrupted`].
    pub fn new(transport: T, form: &FormDescription, stop: Option<watch::Receiver<bool>>) -> Self {
        let nodes = form.node_ids().map(|n| (n, NodeStatus::default())).collect();
        Self {
            transport,
            form: form.clone(),
            nodes,
            unexpected: Vec::new(),
            next_service: Instant::now(),
            watch_liveness: false,
            stop,
        }
    }

    /// The form description.
    pub fn form(&self) -> &FormDescription {
        &self.form
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

    /// Sends one packet.
    pub async fn send(&mut self, packet: Packet) -> Result<(), SessionError> {
        Ok(self.transport.send(packet).await?)
    }

    /// Broadcasts an emergency stop (three times, against a lossy bus).
    pub async fn emergency_stop(&mut self) -> Result<(), SessionError> {
        for _ in 0..3 {
            self.send(Packet::broadcast(Message::EmergencyStop)).await?;
        }
        Ok(())
    }

    fn handle(&mut self, packet: Packet) {
        let Address::Node(node) = packet.address else { return };
        if packet.message.code().direction() != firmware_protocol::message::Direction::NodeToHost {
            return;
        }
        let Some(status) = self.nodes.get_mut(&node) else {
            if !self.unexpected.contains(&node.get()) {
                self.unexpected.push(node.get());
            }
            return;
        };
        status.last_heard = Some(Instant::now());
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
                let first = four.half.first();
                status.positions[first..first + 4].copy_from_slice(&four.positions);
            }
            Message::AllFeedback(all) => status.positions = all.positions,
            Message::Emergency(e) => status.events.push(e),
            Message::Identity(i) => status.identity = Some(i),
            Message::Capabilities(c) => status.capabilities = Some(c),
            _ => {}
        }
    }

    fn stopped(&self) -> bool {
        self.stop.as_ref().is_some_and(|s| *s.borrow())
    }

    /// Receives and handles packets until `done` holds for one (returned) or `deadline`.
    async fn receive_until(
        &mut self,
        deadline: Instant,
        mut done: impl FnMut(&Packet) -> bool,
    ) -> Result<Option<Packet>, SessionError> {
        loop {
            if self.stopped() {
                self.emergency_stop().await?;
                return Err(SessionError::Interrupted);
            }
            if Instant::now() >= deadline {
                return Ok(None);
            }
            let mut stop = self.stop.clone();
            let stop_changed = async {
                match stop.as_mut() {
                    Some(s) => {
                        if s.changed().await.is_err() {
                            std::future::pending::<()>().await;
                        }
                    }
                    None => std::future::pending().await,
                }
            };
            tokio::select! {
                packet = self.transport.recv() => {
                    let packet = packet?;
                    self.handle(packet);
                    if done(&packet) {
                        return Ok(Some(packet));
                    }
                }
                () = sleep_until(deadline) => return Ok(None),
                () = stop_changed => {}
            }
        }
    }

    /// Sends `packet` (addressed to `node`) until an answer for which `answered` holds comes
    /// from it, retrying twice.
    async fn request(
        &mut self,
        packet: Packet,
        name: &'static str,
        mut answered: impl FnMut(&Message) -> bool,
    ) -> Result<Message, SessionError> {
        let node = match packet.address {
            Address::Node(n) => n,
            Address::Broadcast => NodeId::MIN,
        };
        let attempts = ATTEMPTS;
        for _ in 0..attempts {
            self.send(packet).await?;
            let deadline = Instant::now() + answer_timeout(self.link());
            let answer = self
                .receive_until(deadline, |p| {
                    p.address == Address::Node(node) && answered(&p.message)
                })
                .await?;
            if let Some(answer) = answer {
                return Ok(answer.message);
            }
        }
        Err(SessionError::NoAnswer { node: node.get(), request: name, attempts })
    }

    /// Host heartbeats (CAN) or polls (serial) when due.
    async fn service(&mut self) -> Result<(), SessionError> {
        let now = Instant::now();
        if now < self.next_service {
            return Ok(());
        }
        let heartbeat = Message::HostHeartbeat(HostHeartbeat { protocol: PROTOCOL_VERSION });
        if self.link() == Link::Serial {
            self.next_service = now + POLL_PERIOD;
            let nodes: Vec<NodeId> = self.nodes.keys().copied().collect();
            for node in nodes {
                // A lost poll is noticed by liveness, not retried.
                let deadline = Instant::now() + answer_timeout(Link::Serial);
                self.send(Packet::node(node, heartbeat)).await?;
                self.receive_until(deadline, |p| {
                    p.address == Address::Node(node) && matches!(p.message, Message::AllFeedback(_))
                })
                .await?;
            }
        } else {
            self.next_service = now + HEARTBEAT_PERIOD;
            self.send(Packet::broadcast(heartbeat)).await?;
        }
        Ok(())
    }

    /// The first node not heard for [`NODE_LOST_AFTER`].
    fn lost(&self) -> Option<(NodeId, Duration)> {
        let now = Instant::now();
        self.nodes.iter().find_map(|(&node, status)| {
            let silent = now.saturating_duration_since(status.last_heard?);
            (silent > NODE_LOST_AFTER).then_some((node, silent))
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
                && let Some((node, silent)) = self.lost()
            {
                return Err(SessionError::NodeLost { node: node.get(), silent });
            }
            if done(self) {
                return Ok(true);
            }
            if Instant::now() >= deadline {
                return Ok(false);
            }
            // Wake for the next heartbeat or poll, or at least every 10 ms to check.
            let wake =
                deadline.min(self.next_service).min(Instant::now() + Duration::from_millis(10));
            self.receive_until(wake, |_| false).await?;
        }
    }

    /// Identifies `node` (Identity, then Capabilities) and checks it against the description.
    pub async fn identify(&mut self, node: NodeId) -> Result<Vec<NodeProblem>, SessionError> {
        if let Some(status) = self.nodes.get_mut(&node) {
            status.identity = None;
            status.capabilities = None;
        }
        let answer = self
            .request(Packet::node(node, Message::IdentifyRequest), "IdentifyRequest", |m| {
                matches!(m, Message::Capabilities(_))
            })
            .await;
        match answer {
            Ok(_) => {}
            Err(SessionError::NoAnswer { .. }) => {
                return Ok(vec![NodeProblem::Missing(node.get())]);
            }
            Err(e) => return Err(e),
        }
        // The Identity went first; if it was lost, ask again.
        if self.nodes.get(&node).and_then(|s| s.identity).is_none() {
            self.request(Packet::node(node, Message::IdentifyRequest), "IdentifyRequest", |m| {
                matches!(m, Message::Identity(_))
            })
            .await?;
        }
        let status = self.nodes.get(&node).cloned().unwrap_or_default();
        if let Some(status) = self.nodes.get_mut(&node) {
            status.last_heard = Some(Instant::now());
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
        let weakest = |f: &dyn Fn(&sim::form::ActuatorSpec) -> u16| {
            actuators.iter().map(|a| f(a)).min().unwrap_or(0)
        };
        let stroke = weakest(&|a| a.stroke().hundredths_mm());
        mismatch(
            "stroke",
            format!("{} mm", f64::from(caps.stroke.hundredths_mm()) / 100.0),
            format!("{} mm", f64::from(stroke) / 100.0),
        );
        let speed = weakest(&|a| a.max_speed());
        mismatch(
            "max speed",
            format!("{} mm/s", f64::from(caps.max_speed) / 100.0),
            format!("{} mm/s", f64::from(speed) / 100.0),
        );
        let accel = weakest(&|a| a.max_accel());
        mismatch(
            "max acceleration",
            format!("{} mm/s²", f64::from(caps.max_accel) / 10.0),
            format!("{} mm/s²", f64::from(accel) / 10.0),
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
        let packet = Packet::node(node, Message::Control(command));
        let name = match command {
            DriveCommand::Disable => "Disable",
            DriveCommand::Enable => "Enable",
            DriveCommand::FaultReset => "FaultReset",
            DriveCommand::Halt => "Halt",
        };
        let answer = self
            .request(packet, name, |m| matches!(m, Message::Ack(a) if a.request == Code::Control))
            .await?;
        self.expect_ok(node, name, answer)
    }

    fn expect_ok(
        &self,
        node: NodeId,
        name: &'static str,
        answer: Message,
    ) -> Result<(), SessionError> {
        match answer {
            Message::Ack(ack) if ack.status == AckStatus::Ok => Ok(()),
            Message::Ack(ack) => {
                let hint = match self.nodes.get(&node).and_then(|s| s.heartbeat) {
                    Some(h) if !h.faults.is_empty() => {
                        format!(" (node in {:?}, faults {:?})", h.state, h.faults)
                    }
                    Some(h) => format!(" (node in {:?})", h.state),
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

    /// Enables `node` (after a FaultReset if it is in Fault) and homes its actuators whose
    /// home is unknown. Does not wait for homing to finish.
    pub async fn enable(&mut self, node: NodeId) -> Result<(), SessionError> {
        if self
            .nodes
            .get(&node)
            .and_then(|s| s.heartbeat)
            .is_some_and(|h| h.state == DriveState::Fault)
        {
            self.control(node, DriveCommand::FaultReset).await?;
        }
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
            let answer = self
                .request(
                    Packet::node(node, Message::Home(missing)),
                    "Home",
                    |m| matches!(m, Message::Ack(a) if a.request == Code::Home),
                )
                .await?;
            self.expect_ok(node, "Home", answer)?;
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
        // A node that reboots meanwhile is identified and enabled again (a few times).
        for _ in 0..=REENABLES {
            let rebooted =
                |s: &Self| nodes.iter().any(|n| s.nodes.get(n).is_some_and(|s| s.rebooted));
            if self
                .wait_until(deadline, |s| nodes.iter().all(|&n| s.ready(n)) || rebooted(s))
                .await?
                && !rebooted(self)
            {
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
                let state = self.nodes.get(&n).and_then(|s| s.heartbeat);
                format!("node {} ({:?})", n.get(), state.map(|h| (h.state, h.faults)))
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
