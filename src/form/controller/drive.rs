//! A move of the whole form: its options, its report and errors, [`drive`] (set-points in
//! hand), and [`drive_after`] (the set-points computed while the form is held, as `run` and
//! `demo` do). The steps and their checks are "Driving the form" and "The form is claimed
//! before anything is computed" of `docs/controller-and-safety.md`; the claim itself is
//! [`super::claim`].

use std::collections::BTreeMap;
use std::future::Future;
use std::time::Duration;

use firmware_protocol::drive::Faults;
use form_description::FormDescription;
use serde::Serialize;
use tokio::time::Instant;

use super::claim::{Claim, names, newly_stopped};
use super::faults::{self, ANY_FAULT};
use super::forces::{self, ForceSample};
use super::motion::{self, ActuatorReport, MoveError, Progress};
use super::plan::{Clamped, plan};
use super::session::{Cleared, Session, SessionError};
use super::transport::Transport;
use crate::form::setpoints::{OutOfStroke, SetPoints};

/// The default tolerance, mm.
pub const DEFAULT_TOLERANCE_MM: f64 = 0.1;

/// How long past a move's planned duration the actuators may take to arrive by default: a
/// drive's position loop settles in tens of milliseconds; the rest is margin for a node that
/// was busy or a host under load.
pub const DEFAULT_SETTLE: Duration = Duration::from_secs(2);

/// How long homing may take by default: a node homes by creeping to its switch at its homing
/// speed (5 mm/s by default), so the reference form's longest stroke, 60 mm, takes 12 s; 30 s
/// leaves room for a slower homing speed and a node homed last.
pub const DEFAULT_HOMING_TIMEOUT: Duration = Duration::from_secs(30);

/// How a drive runs.
#[derive(Clone, Debug)]
pub struct DriveOptions {
    /// Clamp out-of-stroke set-points instead of refusing them.
    pub clamp: bool,
    /// An actuator within this of its target has arrived, mm (default 0.1).
    pub tolerance_mm: f64,
    /// Multiply the shortest duration by this (default 1: the shortest; values below 1
    /// count as 1).
    pub slower: f64,
    /// The move lasts at least this long (default 0: the shortest).
    pub min_duration: Duration,
    /// How long past the planned duration to wait for every actuator (default 2 s).
    pub settle: Duration,
    /// How long homing may take (default 30 s).
    pub homing_timeout: Duration,
    /// Clear latched hardware faults (a jam, an overcurrent, a broken encoder...) at start;
    /// without it only an emergency stop and a host timeout are cleared (default false).
    pub reset_faults: bool,
    /// Read every actuator's force at rest after the move, for this long (default: no);
    /// needs nodes of protocol 1.1, checked before anything moves.
    pub read_forces: Option<Duration>,
}

impl Default for DriveOptions {
    fn default() -> Self {
        Self {
            clamp: false,
            tolerance_mm: DEFAULT_TOLERANCE_MM,
            slower: 1.0,
            min_duration: Duration::ZERO,
            settle: DEFAULT_SETTLE,
            homing_timeout: DEFAULT_HOMING_TIMEOUT,
            reset_faults: false,
            read_forces: None,
        }
    }
}

/// What a drive did.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct DriveReport {
    /// The form's name.
    pub form: String,
    /// The link (`/dev/ttyUSB0`, `can0`, `simulated bus`).
    pub device: String,
    /// The SYNC's duration, ms.
    pub duration_ms: u64,
    /// From the SYNC to the end of watching, ms.
    pub elapsed_ms: u64,
    /// Every actuator of the set-points, in id order.
    pub actuators: Vec<ActuatorReport>,
    /// Every actuator of the form whose position was known at the end, mm (those the
    /// set-points leave out included): what the form's shape is computed from.
    pub positions_mm: BTreeMap<String, f64>,
    /// Set-points clamped into the stroke: `(id, asked mm, used mm)`.
    pub clamped: Clamped,
    /// Faults cleared at the start, warnings from the nodes (a move too short, ...) and
    /// resumed reboots.
    pub warnings: Vec<String>,
    /// Every actuator's force at rest after the move, by id (with
    /// [`DriveOptions::read_forces`]; empty otherwise).
    #[serde(skip_serializing_if = "BTreeMap::is_empty")]
    pub forces: BTreeMap<String, ForceSample>,
}

impl DriveReport {
    /// Every actuator arrived within tolerance.
    pub fn converged(&self) -> bool {
        self.actuators.iter().all(|a| a.within_tolerance)
    }
}

/// Why a drive failed.
#[derive(Debug, thiserror::Error)]
pub enum DriveError {
    /// The set-points ask for positions outside the stroke (nothing was sent).
    #[error(transparent)]
    OutOfStroke(#[from] OutOfStroke),
    /// The session failed.
    #[error(transparent)]
    Session(#[from] SessionError),
    /// The move failed.
    #[error(transparent)]
    Move(#[from] MoveError),
    /// Forces were asked for, but some nodes measure none (protocol 1.0; nothing moved).
    #[error("node(s) {} speak protocol 1.0 and measure no force: reading forces needs nodes of protocol 1.1 (update their firmware)", crate::messages::list(.0.iter()))]
    NoForce(Vec<u8>),
    /// Some actuators did not arrive within tolerance in time.
    #[error("{} actuators not within tolerance after {} ms: {}", .0.actuators.iter().filter(|a| !a.within_tolerance).count(), .0.elapsed_ms, crate::messages::list(.0.actuators.iter().filter(|a| !a.within_tolerance).map(|a| &a.id)))]
    NotReached(Box<DriveReport>),
}

/// Drives the form to `setpoints`: checks them (refusing or clamping out-of-stroke
/// positions before anything is sent), claims the form ([`Claim::take`]: discovers and
/// checks every node), then drives it ([`Claim::drive`]): clears latched faults as
/// [`DriveOptions::reset_faults`] allows, enables and homes, moves every actuator together,
/// watches until all are within tolerance, then disables. `progress` is called about every
/// 50 ms during the move.
pub async fn drive<T: Transport>(
    transport: T,
    form: &FormDescription,
    setpoints: &SetPoints,
    options: &DriveOptions,
    progress: impl FnMut(&Progress),
) -> Result<DriveReport, DriveError> {
    plan(form, setpoints, options.clamp)?;
    Claim::take(transport, form).await?.drive(setpoints, options, progress).await
}

/// The computation's stack: as large as the main thread's (8 MiB on Linux), where it ran
/// before it had a thread of its own.
const COMPUTE_STACK_BYTES: usize = 8 << 20;

/// Why the computation of [`drive_after`] gave no result.
#[derive(Debug, thiserror::Error)]
pub enum ComputeThreadError {
    /// Its thread could not start.
    #[error("cannot start the computation: {0}")]
    Spawn(std::io::Error),
    /// It ended without a result (it panicked).
    #[error("the computation ended without a result")]
    NoResult,
}

/// Why [`drive_after`] failed, by the step that failed.
#[derive(Debug, thiserror::Error)]
pub enum DriveAfterError<E> {
    /// Claiming the form failed, or the form was stopped or lost while the computation ran
    /// (nothing moved).
    #[error(transparent)]
    Claim(SessionError),
    /// The computation gave no result.
    #[error(transparent)]
    Thread(ComputeThreadError),
    /// The computation failed.
    #[error("{0}")]
    Computation(E),
    /// The drive failed, after the computation.
    #[error(transparent)]
    Drive(DriveError),
}

/// Drives `form` over `transport` through the set-points `compute` returns (one move per
/// step, [`Claim::drive_through`]), with the value it returns beside them.
///
/// The form is claimed before `compute` starts ([`Claim::take`]): every node discovered and
/// the e-stops latched on it recorded. `compute` then runs on a thread of its own (named, with
/// a stack as large as the main thread's) while the link is kept alive
/// ([`Claim::hold_while`]); an e-stop meanwhile — from another terminal, a signal, or latched
/// on a node — ends the drive at once ([`DriveAfterError::Claim`]; the computation is
/// abandoned) and is never cleared by it. Then the form is driven ([`Claim::drive`]), with
/// `beside` run beside the move (a watch of the caller's: if it ends first, the move goes on
/// alone). `progress` is called about every 50 ms during the move.
pub async fn drive_after<T, R, E>(
    transport: T,
    form: &FormDescription,
    options: &DriveOptions,
    compute: impl FnOnce() -> Result<(R, Vec<SetPoints>), E> + Send + 'static,
    progress: impl FnMut(&Progress),
    beside: impl Future<Output = ()>,
) -> Result<(R, Vec<DriveReport>), DriveAfterError<E>>
where
    T: Transport,
    R: Send + 'static,
    E: Send + 'static,
{
    let mut claim = Claim::take(transport, form).await.map_err(DriveAfterError::Claim)?;
    let (computed, result) = tokio::sync::oneshot::channel();
    std::thread::Builder::new()
        .name("dressform compute".into())
        .stack_size(COMPUTE_STACK_BYTES)
        .spawn(move || {
            // The receiver is gone only when the drive already ended (an e-stop).
            let _ = computed.send(compute());
        })
        .map_err(|e| DriveAfterError::Thread(ComputeThreadError::Spawn(e)))?;
    let (value, steps) = match claim.hold_while(result).await {
        Ok(Ok(done)) => done.map_err(DriveAfterError::Computation)?,
        Ok(Err(_)) => return Err(DriveAfterError::Thread(ComputeThreadError::NoResult)),
        Err(stopped) => return Err(DriveAfterError::Claim(stopped)),
    };
    let driving = claim.drive_through(&steps, options, progress);
    tokio::pin!(driving);
    let report = tokio::select! {
        report = &mut driving => report,
        () = beside => driving.await,
    };
    report.map(|report| (value, report)).map_err(DriveAfterError::Drive)
}

impl<T: Transport> Claim<T> {
    /// Drives the form to `setpoints` (see [`drive()`]): checks them, clears the latched
    /// faults [`DriveOptions::reset_faults`] allows — an e-stop only on a node that held it
    /// when the form was claimed — enables and homes, moves every actuator together, watches
    /// until all are within tolerance (and reads the forces at rest, if asked), then
    /// disables.
    pub async fn drive(
        self,
        setpoints: &SetPoints,
        options: &DriveOptions,
        progress: impl FnMut(&Progress),
    ) -> Result<DriveReport, DriveError> {
        let mut reports =
            self.drive_through(std::slice::from_ref(setpoints), options, progress).await?;
        Ok(reports.remove(0))
    }

    /// Drives the form through `steps` in turn, as [`Claim::drive`] drives it to one: every
    /// step checked before anything moves, faults cleared and the form enabled once, then for
    /// each step one synchronised move (and the forces at rest, if asked); disabled at the
    /// end. The first step not reached ends the sequence with [`DriveError::NotReached`].
    /// One report per step.
    pub async fn drive_through(
        self,
        steps: &[SetPoints],
        options: &DriveOptions,
        mut progress: impl FnMut(&Progress),
    ) -> Result<Vec<DriveReport>, DriveError> {
        let (mut session, stopped_at_start) = self.into_parts();
        let form = session.form().clone();
        let plans = steps
            .iter()
            .map(|setpoints| plan(&form, setpoints, options.clamp))
            .collect::<Result<Vec<_>, _>>()?;
        if options.read_forces.is_some() {
            let missing = forces::without_force(&session);
            if !missing.is_empty() {
                return Err(DriveError::NoForce(missing));
            }
        }
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
        let mut reports = Vec::with_capacity(plans.len());
        for (plan, clamped) in plans {
            let started = Instant::now();
            let result = motion::run(
                &mut session,
                &plan,
                &move_options,
                options.homing_timeout,
                &mut progress,
            )
            .await;
            let (duration_ms, actuators, warnings) = match result {
                Ok(done) => done,
                // A session error is the session's, wherever it happened.
                Err(MoveError::Session(e)) => return Err(e.into()),
                Err(e) => return Err(e.into()),
            };
            notes.extend(warnings);
            let elapsed_ms = started.elapsed().as_millis() as u64;
            let forces = match options.read_forces {
                Some(window) => forces::read_forces(&mut session, window, &mut notes).await?,
                None => BTreeMap::new(),
            };
            let report = DriveReport {
                form: form.name.clone(),
                device: device.clone(),
                duration_ms,
                elapsed_ms,
                actuators,
                positions_mm: positions_of(&session),
                clamped,
                warnings: std::mem::take(&mut notes),
                forces,
            };
            if !report.converged() {
                session.disable_all().await?;
                return Err(DriveError::NotReached(Box::new(report)));
            }
            reports.push(report);
        }
        session.disable_all().await?;
        Ok(reports)
    }
}

/// One note per kind of fault cleared: `cleared the latched emergency stop on nodes 1, 2, 3`.
fn cleared_notes(cleared: &[Cleared]) -> Vec<String> {
    let mut by_kind: BTreeMap<String, Vec<String>> = BTreeMap::new();
    for c in cleared {
        by_kind.entry(faults::describe(c.faults)).or_default().push(c.node.address.to_string());
    }
    by_kind
        .into_iter()
        .map(|(what, nodes)| format!("cleared the latched {what} on node(s) {}", nodes.join(", ")))
        .collect()
}

/// Every actuator of the form whose position the session knows, mm.
fn positions_of<T: Transport>(session: &Session<T>) -> BTreeMap<String, f64> {
    session
        .form()
        .axes()
        .filter_map(|a| {
            let p = session.nodes().get(&a.node_id()?)?.positions[a.actuator()?.index()]?;
            Some((a.id.to_string(), p.mm()))
        })
        .collect()
}
