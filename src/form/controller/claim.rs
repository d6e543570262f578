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

use super::motion::{self, MoveError, Progress};
use super::session::{Session, SessionError};
use super::transport::Transport;
use super::{ANY_FAULT, DriveError, DriveOptions, DriveReport, cleared_notes, faults, plan};
use crate::form::setpoints::SetPoints;
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

    /// Drives the form to `setpoints` (see [`super::drive`]): checks them, clears the latched
    /// faults [`DriveOptions::reset_faults`] allows — an e-stop only on a node that held it
    /// when the form was claimed — enables and homes, moves every actuator together, watches
    /// until all are within tolerance, then disables.
    pub async fn drive(
        self,
        setpoints: &SetPoints,
        options: &DriveOptions,
        mut progress: impl FnMut(&Progress),
    ) -> Result<DriveReport, DriveError> {
        let Self { mut session, stopped_at_start } = self;
        let form = session.form().clone();
        let (plan, clamped) = plan(&form, setpoints, options.clamp)?;
        let device = session.device();
        let allowed = if options.reset_faults { ANY_FAULT } else { faults::CLEARED_AT_START };
        let allowed_on = |node| {
            if stopped_at_start.contains(&node) {
                allowed
            } else {
                allowed.difference(Faults::EMERGENCY_STOP)
            }
        };
        // The reset judges on fresh heartbeats and sends nothing when it refuses: an e-stop
        // latched since the start is refused there, and named for what it is.
        let cleared = match session.reset_faults(allowed_on).await {
            Err(SessionError::Latched(_))
                if !newly_stopped(&session, &stopped_at_start).is_empty() =>
            {
                let late = newly_stopped(&session, &stopped_at_start);
                return Err(SessionError::StoppedSinceStart(names(&late)).into());
            }
            result => result?,
        };
        let remaining: Vec<String> = cleared
            .iter()
            .filter(|c| !c.remaining.is_empty())
            .map(|c| format!("{}: {}", c.node, faults::describe(c.remaining)))
            .collect();
        if !remaining.is_empty() {
            return Err(SessionError::NotCleared(remaining).into());
        }
        let mut notes = cleared_notes(&cleared);
        session.enable_all(options.homing_timeout).await?;
        let move_options = motion::MoveOptions {
            tolerance_mm: options.tolerance_mm,
            slower: options.slower,
            min_duration: options.min_duration,
            settle: options.settle,
        };
        let started = Instant::now();
        let result =
            motion::run(&mut session, &plan, &move_options, options.homing_timeout, &mut progress)
                .await;
        let (duration_ms, actuators, warnings) = match result {
            Ok(done) => done,
            // A session error is the session's, wherever it happened.
            Err(MoveError::Session(e)) => return Err(e.into()),
            Err(e) => return Err(e.into()),
        };
        notes.extend(warnings);
        let elapsed_ms = started.elapsed().as_millis() as u64;
        let positions_mm = super::positions_of(&session);
        session.disable_all().await?;
        let report = DriveReport {
            form: form.name.clone(),
            device,
            duration_ms,
            elapsed_ms,
            actuators,
            positions_mm,
            clamped,
            warnings: notes,
        };
        if report.converged() { Ok(report) } else { Err(DriveError::NotReached(Box::new(report))) }
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
fn newly_stopped<T: Transport>(
    session: &Session<T>,
    stopped_at_start: &BTreeSet<NodeId>,
) -> Vec<NodeId> {
    estopped(session).difference(stopped_at_start).copied().collect()
}

/// The nodes' addresses for a message (eight names would not fit its line).
fn names(nodes: &[NodeId]) -> Vec<u8> {
    nodes.iter().map(|n| n.get()).collect()
}
