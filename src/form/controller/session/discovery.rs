//! Discovery: every node of the form description identified (`Identity`, then `Capabilities`)
//! and checked against it — protocol major version, actuator count, stroke, speed and
//! acceleration limits; missing and unexpected nodes. Implements "Driving the form" of
//! `docs/controller-and-safety.md` and the host's side of "Versioning" in
//! `firmware-protocol/README.md` (a node of another major version is reported, never enabled).

use firmware_protocol::version::Compatibility;
use firmware_protocol::{Link, Message, NodeId, PROTOCOL_VERSION, Packet};
use tokio::time::Instant;

use super::requests::answer_timeout;
use super::{NodeStatus, Session, SessionError};
use crate::form::controller::transport::Transport;

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

impl<T: Transport> Session<T> {
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
}
