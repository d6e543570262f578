//! Enabling: every node enabled after a fresh host heartbeat, its unhomed actuators homed, the
//! host waiting until all are Enabled and homed — a node that reboots meanwhile is identified
//! and enabled again, twice at most — and every node disabled at the end (the drives hold the
//! panels). Implements the host's side of "Drive state machine" in
//! `firmware-protocol/README.md` (Enable needs a recent host heartbeat) and "Safety" of
//! `docs/controller-and-safety.md` (a fault during homing is reported at once, as during a
//! move).

use std::time::Duration;

use firmware_protocol::drive::{AckStatus, DriveCommand, DriveState};
use firmware_protocol::message::{Ack, Heartbeat, Param, ParamRead};
use firmware_protocol::param::ParamId;
use firmware_protocol::{Actuator, ActuatorSet, Force, HUNDREDTHS_PER_N, Message, NodeId, Packet};
use tokio::time::Instant;

use super::requests::ATTEMPTS;
use super::{Session, SessionError};
use crate::form::controller::faults;
use crate::form::controller::transport::Transport;

/// How many times a node that reboots while the host waits for it to be ready is enabled
/// again.
const REENABLES: usize = 2;

impl<T: Transport> Session<T> {
    /// The actuators of `node` in the description.
    pub fn actuator_set(&self, node: NodeId) -> ActuatorSet {
        self.form.actuators_of(node).iter().filter_map(|a| a.actuator()).collect()
    }

    /// Enables `node` and homes its actuators whose home is unknown (latched faults are
    /// [`Session::reset_faults`]'s). A node that measures force (protocol 1.1) is first
    /// given its actuators' force limits from the description (a node forgets them when it
    /// reboots, so every enable sets them). Does not wait for homing to finish.
    pub async fn enable(&mut self, node: NodeId) -> Result<(), SessionError> {
        self.set_force_limits(node).await?;
        self.enable_and_home(node).await
    }

    /// Enables `node` and starts homing what needs it (its force limits already set).
    async fn enable_and_home(&mut self, node: NodeId) -> Result<(), SessionError> {
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

    /// Whether `node` measures force: it speaks protocol 1.1 or later (from its identity).
    pub fn measures_force(&self, node: NodeId) -> bool {
        self.nodes.get(&node).and_then(|s| s.identity).is_some_and(|i| i.protocol.has_force())
    }

    /// Writes the description's force limits to `node`'s actuators, if it measures force:
    /// one `ParamWrite` for the whole node when every actuator has the same (the reference
    /// form's panel nodes), else one per actuator that has one (a lift without one keeps the
    /// node's own, its rated force). A limit the node refuses is named with the actuator's
    /// rated force.
    async fn set_force_limits(&mut self, node: NodeId) -> Result<(), SessionError> {
        if !self.measures_force(node) {
            return Ok(());
        }
        let axes = self.form.actuators_of(node);
        let limits: Vec<(Option<Actuator>, Option<Force>)> =
            axes.iter().map(|a| (a.actuator(), a.force_limit())).collect();
        let writes: Vec<(Option<Actuator>, Force)> = match limits.first() {
            Some(&(_, Some(first))) if limits.iter().all(|&(_, l)| l == Some(first)) => {
                vec![(None, first)]
            }
            _ => limits.iter().filter_map(|&(a, l)| Some((a, l?))).collect(),
        };
        for (actuator, limit) in writes {
            let value = i32::from(limit.hundredths_n());
            let write = Param { param: ParamId::FORCE_LIMIT, actuator, value };
            let answer = self.request(Packet::node(node, Message::ParamWrite(write))).await?;
            if let Message::Ack(Ack { status: AckStatus::InvalidArgument, .. }) = answer {
                let rated = self.rated_force(node, actuator.or(limits[0].0)).await?;
                return Err(SessionError::ForceLimit {
                    node: self.node_name(node).to_string(),
                    limit_n: limit.n(),
                    rated_n: rated,
                });
            }
            self.expect_ok(node, "ParamWrite ForceLimit", answer).await?;
        }
        Ok(())
    }

    /// The rated force of `actuator` of `node`, N, if it answers.
    async fn rated_force(
        &mut self,
        node: NodeId,
        actuator: Option<Actuator>,
    ) -> Result<Option<f64>, SessionError> {
        let read = ParamRead { param: ParamId::RATED_FORCE, actuator };
        Ok(match self.request(Packet::node(node, Message::ParamRead(read))).await? {
            Message::ParamValue(p) => Some(f64::from(p.value) / HUNDREDTHS_PER_N),
            _ => None,
        })
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

    /// Enables every node, homes what needs it, and waits until all are ready. Every node's
    /// force limits are set before any node is enabled; a node that fails or faults while
    /// the others are being enabled stops them all (Halt, then each disabled), the fault
    /// named as during a move.
    pub async fn enable_all(&mut self, homing_timeout: Duration) -> Result<(), SessionError> {
        let nodes: Vec<NodeId> = self.nodes.keys().copied().collect();
        for &node in &nodes {
            self.set_force_limits(node).await?;
        }
        for &node in &nodes {
            if let Err(e) = self.enable_and_home(node).await {
                let mut warnings = Vec::new();
                return Err(match self.fault(&mut warnings).await {
                    Ok(Some(fault)) => self.stop_for_fault(fault).await,
                    Ok(None) => match self.halt_all().await {
                        Ok(()) => self.disable_all().await.err().unwrap_or(e),
                        Err(stopped) => stopped,
                    },
                    Err(failed) => failed,
                });
            }
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
}
