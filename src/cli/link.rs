//! Where the form is (`--sim`, `--serial`, `--slcan`, `--can`), which form it is (`--form`,
//! the built-in reference form by default), and owning its link for one command: the control
//! endpoint that lets `dressform estop` reach this process, and the signals that e-stop it.

use std::path::PathBuf;

use dressform::form::controller::control::Endpoint;
use dressform::form::controller::open::{OpenError, OpenLink};
use dressform::form::controller::simulated::{SimConfig, SimDriveError, SimulatedRig};
use dressform::form::controller::{Connection, LinkSpec, Transport};
use form_description::FormDescription;

use super::Failure;
use super::signals::{self, Armed};

/// Where the form is.
#[derive(Debug, Clone, clap::Args)]
#[group(required = true, multiple = false)]
pub struct LinkArgs {
    /// The in-process simulated form (no hardware needed; it lives as long as the command).
    #[arg(long)]
    sim: bool,
    /// A serial port speaking the protocol's serial mapping (1 Mbaud).
    #[arg(long, value_name = "PATH")]
    serial: Option<PathBuf>,
    /// An slcan (Lawicel) USB-CAN adapter on a serial port (classic CAN, 1 Mbit/s).
    #[arg(long, value_name = "PATH")]
    slcan: Option<PathBuf>,
    /// A SocketCAN interface (can0, vcan0...).
    #[arg(long, value_name = "IFACE")]
    can: Option<String>,
}

impl LinkArgs {
    pub fn spec(&self) -> LinkSpec {
        match (&self.serial, &self.slcan, &self.can) {
            (Some(path), _, _) => LinkSpec::Serial(path.clone()),
            (_, Some(path), _) => LinkSpec::Slcan(path.clone()),
            (_, _, Some(iface)) => LinkSpec::Can(iface.clone()),
            _ => LinkSpec::Sim,
        }
    }
}

/// `--form`, shared by every command that needs a form.
#[derive(Debug, Clone, clap::Args)]
pub struct FormArg {
    /// The form description: a TOML file, or a built-in form's name (`reference`, `male`)
    /// where no such file exists [default: the built-in reference form; see
    /// `dressform form show --toml`].
    #[arg(long, value_name = "FORM.toml")]
    form: Option<PathBuf>,
}

impl FormArg {
    /// Loads `--form` (a file, else a built-in form of that name), or the reference form.
    pub fn load(&self) -> Result<FormDescription, Failure> {
        match &self.form {
            Some(path) if !path.exists() => {
                path.to_str().and_then(form_description::builtin).ok_or_else(|| {
                    let names: Vec<&str> =
                        form_description::BUILTIN.iter().map(|(n, _)| *n).collect();
                    Failure::bad_input(format!(
                        "--form {}: no such file, and not a built-in form ({})",
                        path.display(),
                        names.join(", ")
                    ))
                })
            }
            Some(path) => FormDescription::load(path).map_err(Failure::bad_input),
            None => Ok(form_description::reference()),
        }
    }

    /// The description's TOML text: the file's, or the built-in form's with its comments.
    pub fn toml_text(&self) -> Result<String, Failure> {
        match &self.form {
            Some(path) if path.exists() => std::fs::read_to_string(path)
                .map_err(|e| Failure::bad_input(format!("{}: cannot read: {e}", path.display()))),
            Some(path) => Ok(path
                .to_str()
                .and_then(form_description::builtin_toml)
                .unwrap_or_default()
                .into()),
            None => Ok(form_description::REFERENCE_TOML.into()),
        }
    }
}

/// A current-thread runtime for one command.
pub fn runtime() -> Result<tokio::runtime::Runtime, Failure> {
    tokio::runtime::Builder::new_current_thread()
        .enable_all()
        .build()
        .map_err(|e| Failure::other(format!("cannot start the runtime: {e}")))
}

/// A link owned by this process (on hardware, or the simulated form started for it): e-stops
/// from another terminal and from signals reach it until it is dropped.
pub struct Owned {
    pub connection: Connection,
    /// The simulated form, with `--sim`.
    pub rig: Option<SimulatedRig>,
    _armed: Armed,
    // Dropped after the connection's session: the endpoint answers to the end.
    _endpoint: Option<Endpoint>,
}

/// Opens the link `spec` names and owns it: binds its control endpoint first (refusing a link
/// another dressform process owns, before anything is written to the device), then opens it
/// (with `--sim`, starts the simulated `form` as `sim` says) and arms the endpoint and the
/// signals with its gate. Must be called within a tokio runtime.
pub fn own(spec: &LinkSpec, form: &FormDescription, sim: &SimConfig) -> Result<Owned, Failure> {
    built(spec)?;
    let endpoint = Endpoint::bind(spec).map_err(Failure::other)?;
    let OpenLink { connection, rig } = open(spec, form, sim)?;
    if let Some(endpoint) = &endpoint {
        endpoint.arm(connection.gate()).map_err(Failure::other)?;
    }
    let armed = signals::arm(connection.gate());
    Ok(Owned { connection, rig, _armed: armed, _endpoint: endpoint })
}

/// Opens the link `spec` names ([`OpenLink::open`]: with `--sim`, starts the simulated `form`
/// as `sim` says), without owning it. Must be called within a tokio runtime.
pub fn open(spec: &LinkSpec, form: &FormDescription, sim: &SimConfig) -> Result<OpenLink, Failure> {
    built(spec)?;
    OpenLink::open(spec, form, sim).map_err(|e| match e {
        OpenError::Hardware(e) => Failure::other(e),
        OpenError::Sim(e) => sim_failure(e),
    })
}

/// How a simulated form's failure ends the command: its description or faults are bad
/// input (2), its log failed (1), the drive failed as drives do.
pub fn sim_failure(e: SimDriveError) -> Failure {
    match e {
        #[cfg(feature = "simulator")]
        SimDriveError::Sim(_) => Failure::bad_input(e),
        #[cfg(feature = "simulator")]
        SimDriveError::Log { .. } => Failure::other(e),
        #[cfg(feature = "simulator")]
        SimDriveError::Drive(d) => d.into(),
        #[cfg(not(feature = "simulator"))]
        SimDriveError::NotBuilt => Failure::bad_input(e),
    }
}

/// The simulator, as a refusal names what this dressform lacks.
pub const SIMULATOR: &str = "the simulator (cargo feature `simulator`)";
/// SocketCAN, as a refusal names what this dressform lacks.
pub const SOCKETCAN: &str = "SocketCAN (cargo feature `socketcan`)";

/// `what` (`--sim`, `dressform demo`) in a dressform built without `missing` ([`SIMULATOR`],
/// [`SOCKETCAN`]): a one-line refusal, exit status 2.
pub fn not_built(what: &str, missing: &str) -> Failure {
    Failure::bad_input(format!(
        "{what}: this dressform was built without {missing}; rebuild with default features"
    ))
}

/// Refuses a link this dressform was built without (`--sim`, `--can`), before anything is
/// opened.
pub fn built(spec: &LinkSpec) -> Result<(), Failure> {
    match spec {
        LinkSpec::Sim if cfg!(not(feature = "simulator")) => Err(not_built("--sim", SIMULATOR)),
        LinkSpec::Can(_) if cfg!(not(feature = "socketcan")) => Err(not_built("--can", SOCKETCAN)),
        _ => Ok(()),
    }
}
