//! `dressform status`: the state of every node, read without changing it (identified,
//! listened to; problems against the description reported, not fatal). See "Recovery" in
//! `docs/controller-and-safety.md`.

use std::time::Duration;

use firmware_protocol::NodeId;
use form_description::FormDescription;
use serde::Serialize;
use tokio::time::Instant;

use super::faults::{self, fault_names, state_name};
use super::session::{NodeProblem, Session, SessionError};
use super::transport::Transport;

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
                        (a.id.to_string(), p.map(|p| p.mm()))
                    })
                    .collect(),
                problems: problems.iter().map(ToString::to_string).collect(),
            }
        })
        .collect();
    Ok(reports)
}
