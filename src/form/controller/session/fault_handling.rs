//! Faults: found one way during homing and during a move ([`Session::fault`]): an `Emergency`
//! event with a fault code, or a heartbeat in Fault; the session halts every node, then
//! disables each ([`Session::stop_for_fault`]: none stays Enabled to latch a host timeout once
//! the host is gone), and reports the node and actuator in words. Latched faults found at the
//! start are cleared by [`Session::reset_faults`] only within what the caller allows (see
//! [`crate::form::controller::faults`]). Implements "Recovery" of
//! `docs/controller-and-safety.md` and the host's side of "Faults and emergency events" in
//! `firmware-protocol/README.md` (an unknown code is a fault only when the node is in Fault).

use std::collections::BTreeSet;
use std::time::Duration;

use firmware_protocol::drive::{DriveCommand, DriveState, EmergencyCode, Faults};
use firmware_protocol::{Address, Code, Link, Message, NodeId, Packet, timing};
use tokio::time::Instant;

use super::requests::answer_timeout;
use super::{Session, SessionError};
use crate::form::controller::faults::{self, Fault, NodeName};
use crate::form::controller::transport::Transport;

/// How long to wait for the `Emergency` event of a node seen in Fault (on serial it comes
/// after the heartbeat, in the same poll answer; two poll periods leave room).
const EVENT_GRACE: Duration = Duration::from_millis(2 * timing::FEEDBACK_PERIOD_MS as u64);

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

impl<T: Transport> Session<T> {
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
                .filter_map(|e| self.form.actuator_at(node, e.actuator?).map(|a| a.id.to_string()))
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
                    .and_then(|a| self.form.actuator_at(node, a).map(|spec| spec.id.to_string()));
                // An unknown code is a fault if the node is in Fault (firmware-protocol/README.md, "Faults and emergency events").
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

    /// Broadcasts `Halt`: every node stops its moves and homing, and stays Enabled. On CAN
    /// every node answers a broadcast with an `Ack` naming `Control`; those answers are taken
    /// here (for at most an answer's time), so that none is taken later for the answer to a
    /// `Control` sent to one node (a `Disable` that has not reached it yet).
    pub async fn halt_all(&mut self) -> Result<(), SessionError> {
        self.send(Packet::broadcast(Message::Control(DriveCommand::Halt))).await?;
        if self.link() == Link::Serial {
            return Ok(());
        }
        let mut waiting: BTreeSet<NodeId> = self.nodes.keys().copied().collect();
        let deadline = Instant::now() + answer_timeout(self.link());
        self.receive_until(deadline, |p| {
            if let (Address::Node(node), Message::Ack(ack)) = (p.address, p.message)
                && ack.request == Code::Control
            {
                waiting.remove(&node);
            }
            waiting.is_empty()
        })
        .await?;
        Ok(())
    }
}
