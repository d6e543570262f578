//! The simulated form's types as the rest of the controller names them, in a dressform built
//! without the simulator (cargo feature `simulator`): one path opens every link in both
//! builds, and here [`SimulatedRig::start`] refuses, so no simulated form is ever made.

use std::path::PathBuf;

use form_description::FormDescription;
use form_description::garment::GarmentSpec;

use super::transport::Connection;

/// The simulated form to drive: the simulator's fields, of which only the log's path can hold
/// anything in this build.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SimConfig {
    /// The bus's kind: none.
    pub kind: (),
    /// Faults to inject: none can be given.
    pub faults: FaultSpec,
    /// Simulation options: none.
    pub options: (),
    /// Write a candump log of the bus here.
    pub log: Option<PathBuf>,
}

impl SimConfig {
    /// As in the simulator's build; here no simulated form exists to wear it.
    pub fn wearing(self, _garment: Option<GarmentSpec>) -> Self {
        self
    }
}

/// A fault spec: in this build, none parses.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct FaultSpec;

impl std::str::FromStr for FaultSpec {
    type Err = SimDriveError;

    fn from_str(_: &str) -> Result<Self, SimDriveError> {
        Err(SimDriveError::NotBuilt)
    }
}

/// Why a simulated form could not start.
#[derive(Debug, thiserror::Error)]
pub enum SimDriveError {
    /// This dressform has no simulator.
    #[error("this dressform was built without the simulator (cargo feature `simulator`)")]
    NotBuilt,
}

/// A simulated form on its bus: none can exist in this build.
#[derive(Debug)]
pub enum SimulatedRig {}

impl SimulatedRig {
    /// Refuses: this build has no simulated form.
    pub fn start(_: &FormDescription, _: &SimConfig) -> Result<Self, SimDriveError> {
        Err(SimDriveError::NotBuilt)
    }

    /// The host's link to the form, as a [`Connection`].
    pub fn connect(&self) -> Connection {
        match *self {}
    }

    /// The log's first write error so far.
    pub fn log_failure(&self) -> Option<SimDriveError> {
        match *self {}
    }

    /// Writes out the log.
    pub fn finish(self) -> Result<(), SimDriveError> {
        match self {}
    }
}
