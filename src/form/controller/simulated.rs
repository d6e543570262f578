//! The controller on the in-process simulated form (`form_sim::robot` on a `form_sim::bus::can`
//! bus): try a set-point file without hardware, or chain mannequin → set-points → drive in tests
//! and demos.
//!
//! A [`SimulatedRig`] is the form and its bus, living as long as the caller keeps it (one
//! command of the CLI); [`drive_on_sim`] drives a fresh one inside a tokio runtime
//! (deterministic under a paused clock).

use std::path::PathBuf;

use form_description::FormDescription;
use form_description::garment::GarmentSpec;
use form_sim::bus::can::{CanBus, CanKind};
use form_sim::bus::candump::CandumpLog;
use form_sim::fault::FaultSpec;
use form_sim::robot::{FormState, SimError, SimOptions, SimulatedForm};

use super::transport::Connection;
use super::transport::sim::SimBus;
use super::{DriveError, DriveOptions, DriveReport, Progress, drive};
use crate::form::setpoints::SetPoints;

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

impl SimConfig {
    /// The same form wearing `garment` from power-on (`None`: as configured).
    pub fn wearing(mut self, garment: Option<GarmentSpec>) -> Self {
        if garment.is_some() {
            self.options.garment = garment;
        }
        self
    }
}

/// Why a simulated drive failed.
#[derive(Debug, thiserror::Error)]
pub enum SimDriveError {
    /// The simulated form could not start (a fault spec naming what the form lacks).
    #[error(transparent)]
    Sim(#[from] SimError),
    /// The candump log could not be created or written.
    #[error("candump log {}: {message}", path.display())]
    Log {
        /// The log file.
        path: PathBuf,
        /// What went wrong.
        message: String,
    },
    /// The drive failed.
    #[error(transparent)]
    Drive(#[from] DriveError),
}

/// A simulated form on its bus (with the bus's log), running until dropped.
#[derive(Debug)]
pub struct SimulatedRig {
    // Declared first: the nodes stop before the bus.
    form: SimulatedForm,
    bus: CanBus,
    log: Option<PathBuf>,
}

impl SimulatedRig {
    /// Powers `form` on as `config` says. Must be called within a tokio runtime.
    pub fn start(form: &FormDescription, config: &SimConfig) -> Result<Self, SimDriveError> {
        let log =
            match &config.log {
                Some(path) => Some(CandumpLog::create(path, "can0").map_err(|e| {
                    SimDriveError::Log { path: path.clone(), message: e.to_string() }
                })?),
                None => None,
            };
        let bus = CanBus::with(config.kind, &config.faults, log);
        let form = SimulatedForm::on_can(form, &bus, &config.faults, &config.options)?;
        Ok(Self { form, bus, log: config.log.clone() })
    }

    /// The host's link to the form.
    pub fn attach(&self) -> SimBus {
        SimBus::attach(&self.bus)
    }

    /// The host's link to the form, as a [`Connection`].
    pub fn connect(&self) -> Connection {
        Connection::Sim(self.attach())
    }

    /// The truth about every node and actuator now.
    pub fn truth(&self) -> FormState {
        self.form.state()
    }

    /// The log's first write error so far (a full disk...), naming the file.
    pub fn log_failure(&self) -> Option<SimDriveError> {
        let path = self.log.clone()?;
        self.bus.log_failure().map(|message| SimDriveError::Log { path, message })
    }

    /// Writes out the log; returns the truth at the end.
    pub fn finish(self) -> Result<FormState, SimDriveError> {
        let truth = self.form.state();
        match (&self.log, self.bus.flush_log()) {
            (Some(path), Err(e)) => {
                Err(SimDriveError::Log { path: path.clone(), message: e.to_string() })
            }
            _ => Ok(truth),
        }
    }
}

/// Drives a fresh simulated `form` to `setpoints`; returns the report and the simulated
/// truth at the end. Must run within a tokio runtime.
pub async fn drive_on_sim(
    form: &FormDescription,
    setpoints: &SetPoints,
    options: &DriveOptions,
    config: &SimConfig,
    progress: impl FnMut(&Progress),
) -> Result<(DriveReport, FormState), SimDriveError> {
    let rig = SimulatedRig::start(form, config)?;
    let result = drive(rig.attach(), form, setpoints, options, progress).await;
    let truth = rig.finish()?;
    Ok((result?, truth))
}
