//! The form claimed for one whole command: from the command's start, before it computes
//! anything, to the end of its move.
//!
//! A command that computes before it moves the form (`run`, `demo`: the body model's fit and
//! the mannequin take seconds) must not undo an e-stop pressed meanwhile. So the command
//! claims the form first ([`Claim::take`]): the link is open (its control endpoint answers,
//! signals e-stop it), every node is discovered, and the e-stops latched on the nodes then are
//! recorded: from a heartbeat of every node heard after the discovery. (Not from the first
//! heartbeat heard: on a loaded machine a pseudo-terminal can deliver a node's heartbeat from
//! before an earlier command's stop after this command opened the link, and a stop latched
//! before the claim ended is one the command could not have known of when it started.) While the command computes, [`Claim::hold_while`] keeps the
//! link alive (host heartbeats, polls, liveness) and ends the command as soon as the link is
//! e-stopped or an e-stop latches on a node that had none at the start (`dressform estop`
//! falling back to the link itself, a stop button on the form). When the move starts
//! ([`Claim::drive`]), only an e-stop already latched at the command's start may be cleared;
//! one latched later ends the command with [`SessionError::StoppedSinceStart`] and is never
//! cleared by it.

use std::collections::BTreeSet;
use std::future::Future;
use std::time::Duration;

use firmware_protocol::NodeId;
use firmware_protocol::drive::Faults;
use tokio::time::Instant;

use super::session::{Session, SessionError};
use super::transport::Transport;
use form_description::FormDescription;

/// How long one wait of [`Claim::hold_while`] lasts before it starts the next (the wait ends
/// sooner when the work is done; any length works, this keeps deadlines far from overflow).
const HOLD_SLICE: Duration = Duration::from_secs(1);

/// A form claimed for one command.
#[derive(Debug)]
pub struct Claim<T> {
    session: Session<T>,
    /// The nodes that held a latched e-stop when the command claimed the form: the only
    /// e-stops the command may clear.
    stopped_at_start: BTreeSet<NodeId>,
}

impl<T: Transport> Claim<T> {
    /// Claims the form over `transport`: discovers every node and checks it against `form`,
    /// then records which nodes hold a latched e-stop (from a heartbeat of each heard after
    /// the discovery).
    pub async fn take(transport: T, form: &FormDescription) -> Result<Self, SessionError> {
        let mut session = Session::new(transport, form);
        session.discover().await?;
        session.refresh().await?;
        let stopped_at_start = estopped(&session);
        Ok(Self { session, stopped_at_start })
    }

    /// Runs `work` while keeping the link alive (heartbeats, polls, liveness). Ends early with
    /// an error when the link is e-stopped ([`SessionError::Stopped`]), an e-stop latches on a
    /// node that had none at the start ([`SessionError::StoppedSinceStart`]), or the link
    /// fails; `work` is then dropped unfinished.
    pub async fn hold_while<F: Future>(&mut self, work: F) -> Result<F::Output, SessionError> {
        let Self { session, stopped_at_start } = self;
        let fresh_stop = |s: &Session<T>| !newly_stopped(s, stopped_at_start).is_empty();
        let watch = async {
            loop {
                if session.wait_until(Instant::now() + HOLD_SLICE, fresh_stop).await? {
                    return Err(SessionError::StoppedSinceStart(names(&newly_stopped(
                        session,
                        stopped_at_start,
                    ))));
                }
            }
        };
        tokio::select! {
            biased;
            failed = watch => failed,
            done = work => Ok(done),
        }
    }

    /// The session and the nodes that held a latched e-stop when the form was claimed: what
    /// the drive ([`Claim::drive`]) goes on from.
    pub(super) fn into_parts(self) -> (Session<T>, BTreeSet<NodeId>) {
        (self.session, self.stopped_at_start)
    }
}

/// The nodes whose last heartbeat shows a latched e-stop.
fn estopped<T: Transport>(session: &Session<T>) -> BTreeSet<NodeId> {
    session
        .nodes()
        .iter()
        .filter(|(_, s)| s.heartbeat.is_some_and(|h| h.faults.contains(Faults::EMERGENCY_STOP)))
        .map(|(&n, _)| n)
        .collect()
}

/// The nodes holding a latched e-stop that they did not hold at the start.
pub(super) fn newly_stopped<T: Transport>(
    session: &Session<T>,
    stopped_at_start: &BTreeSet<NodeId>,
) -> Vec<NodeId> {
    estopped(session).difference(stopped_at_start).copied().collect()
}

/// The nodes' addresses for a message (eight names would not fit its line).
pub(super) fn names(nodes: &[NodeId]) -> Vec<u8> {
    nodes.iter().map(|n| n.get()).collect()
}
