//! Opening the link a [`LinkSpec`] names, whichever it is: a hardware link
//! ([`Connection::open`]) or, for [`LinkSpec::Sim`], a simulated form started for it
//! ([`SimulatedRig`]), which lives as long as the [`OpenLink`] that holds it.

use form_description::FormDescription;

use super::simulated::{SimConfig, SimDriveError, SimulatedRig};
use super::transport::{Connection, LinkSpec, TransportError};

/// An open link to a form, real or simulated.
#[derive(Debug)]
pub struct OpenLink {
    /// The host's side of the link (declared first: it closes before the simulated form
    /// stops).
    pub connection: Connection,
    /// The simulated form behind [`LinkSpec::Sim`]; `None` on hardware.
    pub rig: Option<SimulatedRig>,
}

/// Why a link could not be opened.
#[derive(Debug, thiserror::Error)]
pub enum OpenError {
    /// The device or interface could not be opened.
    #[error(transparent)]
    Hardware(#[from] TransportError),
    /// The simulated form could not start.
    #[error(transparent)]
    Sim(#[from] SimDriveError),
}

impl OpenLink {
    /// Opens `spec`; for [`LinkSpec::Sim`], starts the simulated `form` as `sim` says (must
    /// be called within a tokio runtime). `form` and `sim` are not used on hardware.
    pub fn open(
        spec: &LinkSpec,
        form: &FormDescription,
        sim: &SimConfig,
    ) -> Result<Self, OpenError> {
        if *spec != LinkSpec::Sim {
            return Ok(OpenLink { connection: Connection::open(spec)?, rig: None });
        }
        let rig = SimulatedRig::start(form, sim)?;
        Ok(OpenLink { connection: rig.connect(), rig: Some(rig) })
    }
}
