//! The controller on the in-process simulated form (`sim::robot` on a `sim::bus::can` bus):
//! try a set-point file without hardware, or chain mannequin → set-points → drive in tests
//! and demos.
//!
//! [`drive_on_sim`] runs inside a tokio runtime (deterministic under a paused clock);
//! [`drive_simulated`] starts a real-time runtime of its own.

use std::path::PathBuf;

use sim::bus::can::{CanBus, CanKind};
use sim::bus::candump::CandumpLog;
use sim::fault::FaultSpec;
use sim::form::FormDescription;
use sim::robot::{FormState, SimError, SimOptions, SimulatedForm};

use super::transport::sim::SimBus;
use super::{DriveError, DriveOptions, DriveReport, Progress, drive};
use crate::setpoints::SetPoints;

/// The simulated form to drive.
#[derive(Clone, Debug, PartialEq)]
pub struct SimConfig {
    /// Classic CAN or CAN FD, and the bit rate (default classic, 1 Mbit/s).
    pub kind: CanKind,
    /// Faults to inject (default none).
    pub faults: FaultSpec,
    /// Simulation options.
    pub options: SimOptions,
    /// Write a candump log of the bus here.
    pub log: Option<PathBuf>,
}

impl Default for SimConfig {
    fn default() -> Self {
        Self {
            kind: CanKind::CLASSIC_1M,
            faults: FaultSpec::default(),
            options: SimOptions::default(),
            log: None,
        }
    }
}

/// Why a simulated drive failed.
#[derive(Debug, thiserror::Error)]
pub enum SimDriveError {
    /// The simulated form could not start (invalid form or fault spec).
    #[error(transparent)]
    Sim(#[from] SimError),
    /// The log could not be written, or no runtime started.
    #[error("{0}")]
    Io(String),
    /// The drive failed.
    #[error(transparent)]
    Drive(#[from] DriveError),
}

/// Drives a simulated `form` to `setpoints`; returns the report and the simulated truth at
/// the end. Must run within a tokio runtime.
pub async fn drive_on_sim(
    form: &FormDescription,
    setpoints: &SetPoints,
    options: &DriveOptions,
    config: &SimConfig,
    progress: impl FnMut(&Progress),
) -> Result<(DriveReport, FormState), SimDriveError> {
    let log = match &config.log {
        Some(path) => Some(
            CandumpLog::create(path, "can0")
                .map_err(|e| SimDriveError::Io(format!("{}: {e}", path.display())))?,
        ),
        None => None,
    };
    let bus = CanBus::with(config.kind, &config.faults, log);
    let simulated = SimulatedForm::on_can(form, &bus, &config.faults, &config.options)?;
    let result = drive(SimBus::attach(&bus), form, setpoints, options, progress).await;
    let truth = simulated.state();
    bus.flush_log().map_err(|e| SimDriveError::Io(format!("candump log: {e}")))?;
    Ok((result?, truth))
}

/// [`drive_on_sim`] on a real-time runtime of its own (no runtime needed by the caller).
pub fn drive_simulated(
    form: &FormDescription,
    setpoints: &SetPoints,
    options: &DriveOptions,
    config: &SimConfig,
    progress: impl FnMut(&Progress),
) -> Result<(DriveReport, FormState), SimDriveError> {
    let runtime = tokio::runtime::Builder::new_current_thread()
        .enable_all()
        .build()
        .map_err(|e| SimDriveError::Io(format!("cannot start the runtime: {e}")))?;
    runtime.block_on(drive_on_sim(form, setpoints, options, config, progress))
}
