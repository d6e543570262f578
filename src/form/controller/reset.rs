//! `dressform reset`: every latched fault whose cause is gone cleared, on request only (CiA
//! 402: a fault is cleared only by an explicit FaultReset from the host). See "Recovery" in
//! `docs/controller-and-safety.md`.

use firmware_protocol::NodeId;
use form_description::FormDescription;

use super::faults::ANY_FAULT;
use super::session::{Cleared, NodeProblem, Session, SessionError};
use super::transport::Transport;

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
