//! Serving a simulated form on a pseudo-terminal, for a host to connect to as to real
//! hardware: the library side of `dressform sim`.
//!
//! * [`Transport::SerialPty`]: the form's nodes behind the protocol's serial mapping (1
//!   Mbaud timing); the host opens the slave path as a USB-serial or RS-485 adapter and
//!   polls the nodes.
//! * [`Transport::SlcanPty`]: the nodes on an in-process classic CAN bus at 1 Mbit/s behind
//!   an slcan adapter ([`crate::bus::slcan`]); the host opens the slave path as a USB-CAN
//!   adapter (python-can `interface="slcan"`, `slcand`).
//!
//! ```no_run
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! use sim::serve::{ServeConfig, Transport};
//!
//! let mut config = ServeConfig::new(sim::form::reference(), Transport::SlcanPty);
//! config.log = Some("traffic.log".into());
//! config.faults = "drop=0.01".parse()?;
//! sim::serve::run_until_ctrl_c(config, |device| println!("{}", device.display()))?;
//! # Ok(()) }
//! ```
//!
//! In async code, [`serve`] starts the form and returns a [`Server`];
//! [`Server::run_until`] runs it until a future completes, then stops it and writes out the
//! log.

use std::future::Future;
use std::io;
use std::path::{Path, PathBuf};

use tokio::sync::oneshot;
use tokio::task::JoinHandle;

use crate::bus::can::{BusStats, CanBus, CanKind};
use crate::bus::candump::CandumpLog;
use crate::bus::pty::Pty;
use crate::bus::serial::{DEFAULT_BAUD, SerialLine};
use crate::bus::slcan::SlcanAdapter;
use crate::fault::FaultSpec;
use crate::form::{FormDescription, FormError};
use crate::robot::{SimError, SimOptions, SimulatedForm};

/// How the host connects.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Transport {
    /// The protocol's serial mapping on a pty.
    SerialPty,
    /// A classic CAN bus behind an slcan adapter on a pty.
    SlcanPty,
}

/// What to serve, and how.
#[derive(Clone, Debug, PartialEq)]
pub struct ServeConfig {
    /// The form.
    pub form: FormDescription,
    /// How the host connects.
    pub transport: Transport,
    /// Where to write a candump log of the traffic.
    pub log: Option<PathBuf>,
    /// The run's faults.
    pub faults: FaultSpec,
    /// Simulation options.
    pub options: SimOptions,
}

impl ServeConfig {
    /// `form` on `transport`, without log or faults, with default options.
    pub fn new(form: FormDescription, transport: Transport) -> Self {
        Self {
            form,
            transport,
            log: None,
            faults: FaultSpec::default(),
            options: SimOptions::default(),
        }
    }
}

/// Why the form could not be served.
#[derive(Debug, thiserror::Error)]
pub enum ServeError {
    /// The form or its faults are invalid.
    #[error(transparent)]
    Sim(#[from] SimError),
    /// The pseudo-terminal could not be opened or failed.
    #[error("pseudo-terminal: {0}")]
    Pty(io::Error),
    /// No tokio runtime could be started.
    #[error("cannot start the runtime: {0}")]
    Runtime(io::Error),
    /// The log could not be created or written.
    #[error("candump log {}: {source}", path.display())]
    Log {
        /// The log file.
        path: PathBuf,
        /// Why.
        source: io::Error,
    },
}

/// A form being served.
#[derive(Debug)]
pub struct Server {
    device: PathBuf,
    log: Option<PathBuf>,
    // Declared first: the nodes stop before the bus.
    form: SimulatedForm,
    /// The task moving the bytes (the serial line, or the slcan adapter); `None` once it has
    /// been awaited.
    task: Option<JoinHandle<Result<(), ServeError>>>,
    /// Ends the serial line task (which then writes out its log).
    stop: Option<oneshot::Sender<()>>,
    /// The CAN bus behind the slcan adapter (it holds the log).
    bus: Option<CanBus>,
}

fn log_error(path: &Option<PathBuf>) -> impl FnOnce(io::Error) -> ServeError + use<> {
    let path = path.clone().unwrap_or_default();
    move |source| ServeError::Log { path, source }
}

fn joined(
    result: Result<Result<(), ServeError>, tokio::task::JoinError>,
) -> Result<(), ServeError> {
    result.unwrap_or_else(|e| Err(ServeError::Pty(io::Error::other(e))))
}

/// Starts serving: opens the pty (and the log), powers the form on. Must be called within a
/// tokio runtime; the form runs until the [`Server`] is stopped or dropped.
pub fn serve(config: ServeConfig) -> Result<Server, ServeError> {
    let ServeConfig { form, transport, log: log_path, faults, options } = config;
    // Refuse a bad form or fault spec before creating anything.
    form.validate()
        .map_err(|problems| SimError::from(FormError::Invalid { path: None, problems }))?;
    faults.check(&form).map_err(SimError::from)?;
    let pty = Pty::open().map_err(ServeError::Pty)?;
    let device = pty.path().to_path_buf();
    let interface = match transport {
        Transport::SerialPty => "serial0",
        Transport::SlcanPty => "can0",
    };
    let log = match &log_path {
        Some(path) => Some(
            CandumpLog::create(path, interface)
                .map_err(|source| ServeError::Log { path: path.clone(), source })?,
        ),
        None => None,
    };
    let server = match transport {
        Transport::SerialPty => {
            let form = SimulatedForm::on_serial(&form, &faults, &options)?;
            let line = SerialLine::new(pty, DEFAULT_BAUD, &faults, log);
            let (stop, stopped) = oneshot::channel();
            let serving = form.serve_serial(line, options.tick, stopped);
            let log_error = log_error(&log_path);
            let task = tokio::spawn(async move {
                let (line, log) = serving.await;
                line.map_err(ServeError::Pty)?;
                log.map_err(log_error)
            });
            Server { device, log: log_path, form, task: Some(task), stop: Some(stop), bus: None }
        }
        Transport::SlcanPty => {
            let bus = CanBus::with(CanKind::CLASSIC_1M, &faults, log);
            let form = SimulatedForm::on_can(&form, &bus, &faults, &options)?;
            let adapter = SlcanAdapter::new(pty, &bus);
            let task = tokio::spawn(async move { adapter.run().await.map_err(ServeError::Pty) });
            Server { device, log: log_path, form, task: Some(task), stop: None, bus: Some(bus) }
        }
    };
    Ok(server)
}

impl Server {
    /// The pseudo-terminal path the host opens (`/dev/pts/N`).
    pub fn device_path(&self) -> &Path {
        &self.device
    }

    /// The running form (ground truth for tests).
    pub fn form(&self) -> &SimulatedForm {
        &self.form
    }

    /// The CAN bus's counters (slcan only).
    pub fn bus_stats(&self) -> Option<BusStats> {
        self.bus.as_ref().map(CanBus::stats)
    }

    /// Serves until `stop` completes (or the pty fails), then stops and writes out the log.
    pub async fn run_until(mut self, stop: impl Future<Output = ()>) -> Result<(), ServeError> {
        let failed = match self.task.as_mut() {
            Some(task) => tokio::select! {
                result = task => Some(joined(result)),
                () = stop => None,
            },
            None => None,
        };
        if failed.is_some() {
            self.task = None;
        }
        let stopped = self.shutdown().await;
        failed.unwrap_or(Ok(())).and(stopped)
    }

    /// Stops serving and writes out the log.
    pub async fn shutdown(mut self) -> Result<(), ServeError> {
        if let Some(stop) = self.stop.take() {
            // Gone if the task already ended.
            let _ = stop.send(());
        }
        let result = match self.task.take() {
            // The serial line ends on `stop`; the slcan adapter would run on.
            Some(task) if self.bus.is_none() || task.is_finished() => joined(task.await),
            Some(task) => {
                task.abort();
                Ok(())
            }
            None => Ok(()),
        };
        let flushed = match &self.bus {
            Some(bus) => bus.flush_log().map_err(log_error(&self.log)),
            None => Ok(()),
        };
        result.and(flushed)
    }
}

impl Drop for Server {
    /// Stops serving (the log is written out as far as it can be, errors unreported; use
    /// [`Server::shutdown`] to see them).
    fn drop(&mut self) {
        if let Some(task) = &self.task {
            task.abort();
        }
    }
}

/// Serves `config` until Ctrl-C, on a runtime of its own; `ready` gets the device path
/// once the host can connect. What `dressform sim` calls.
pub fn run_until_ctrl_c(config: ServeConfig, ready: impl FnOnce(&Path)) -> Result<(), ServeError> {
    let runtime = tokio::runtime::Builder::new_current_thread()
        .enable_all()
        .build()
        .map_err(ServeError::Runtime)?;
    runtime.block_on(async {
        let server = serve(config)?;
        ready(server.device_path());
        server
            .run_until(async {
                // Without a signal handler there is nothing to wait for but the pty failing.
                if tokio::signal::ctrl_c().await.is_err() {
                    std::future::pending::<()>().await;
                }
            })
            .await
    })
}
