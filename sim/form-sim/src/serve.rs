//! Serving a simulated form on a pseudo-terminal, for a host to connect to as to real
//! hardware: the library side of `dressform sim`.
//!
//! * [`PtyLink::SerialPty`]: the form's nodes behind the protocol's serial mapping (1
//!   Mbaud timing); the host opens the slave path as a USB-serial or RS-485 adapter and
//!   polls the nodes.
//! * [`PtyLink::SlcanPty`]: the nodes on an in-process classic CAN bus at 1 Mbit/s behind
//!   an slcan adapter ([`crate::bus::slcan`]); the host opens the slave path as a USB-CAN
//!   adapter (python-can `interface="slcan"`, `slcand`).
//!
//! ```no_run
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! use form_sim::serve::{ServeConfig, PtyLink};
//!
//! let mut config = ServeConfig::new(form_description::reference(), PtyLink::SlcanPty);
//! config.log = Some("traffic.log".into());
//! config.faults = "drop=0.01".parse()?;
//! form_sim::serve::run_until_ctrl_c(config, |device| println!("{}", device.display()))?;
//! # Ok(()) }
//! ```
//!
//! [`serve`] starts the form on a thread of its own and returns a [`Server`] (in async code,
//! [`Server::run_until`] serves until a future completes); [`Server::shutdown`] stops it and
//! writes out the log.
//!
//! **Its own thread.** The form runs on an OS thread of its own with a single-threaded tokio
//! runtime, whoever calls [`serve`] (a test process busy with other tests, a host's runtime
//! in the same process): nothing else runs there, so a loaded caller does not make a healthy
//! simulated node answer late — as a node's own microcontroller is never held up by the host.
//! The nodes' watchdogs leave out the pty's own stalls (the kernel holding its bytes on a busy
//! machine, measured by a [`Canary`]), which no wire has.

use std::future::Future;
use std::io;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;

use tokio::sync::oneshot;

use crate::bus::can::{BusStats, CanBus, CanKind};
use crate::bus::candump::CandumpLog;
use crate::bus::pty::{Canary, Pty};
use crate::bus::serial::{DEFAULT_BAUD, SerialLine};
use crate::bus::slcan::SlcanAdapter;
use crate::fault::FaultSpec;
use crate::robot::{SimError, SimOptions, SimulatedForm};
use form_description::FormDescription;

/// How the host connects to the served form: which link runs on the pty (not the host's
/// `Transport` trait, which a served form's host uses over either).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PtyLink {
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
    pub transport: PtyLink,
    /// Where to write a candump log of the traffic.
    pub log: Option<PathBuf>,
    /// The run's faults.
    pub faults: FaultSpec,
    /// Simulation options.
    pub options: SimOptions,
}

impl ServeConfig {
    /// `form` on `transport`, without log or faults, with default options.
    pub fn new(form: FormDescription, transport: PtyLink) -> Self {
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

/// A form being served on its thread.
#[derive(Debug)]
pub struct Server {
    device: PathBuf,
    // Declared first: the nodes stop before the bus.
    form: SimulatedForm,
    /// The CAN bus behind the slcan adapter (for its counters).
    bus: Option<Arc<CanBus>>,
    /// Ends the form's thread (which then writes out the log); `None` once sent.
    stop: Option<oneshot::Sender<()>>,
    /// Resolves (closed) when the form's thread ends, on `stop` or on a failure.
    ended: oneshot::Receiver<()>,
    /// The form's thread, with what it ends with; `None` once joined.
    thread: Option<JoinHandle<Result<(), ServeError>>>,
}

/// What the form's thread hands back once the host can connect.
struct Started {
    device: PathBuf,
    form: SimulatedForm,
    bus: Option<Arc<CanBus>>,
}

fn log_error(path: &Option<PathBuf>) -> impl FnOnce(io::Error) -> ServeError + use<> {
    let path = path.clone().unwrap_or_default();
    move |source| ServeError::Log { path, source }
}

/// How the form's thread ended.
fn joined(thread: JoinHandle<Result<(), ServeError>>) -> Result<(), ServeError> {
    thread
        .join()
        .unwrap_or_else(|_| Err(ServeError::Pty(io::Error::other("the simulator panicked"))))
}

/// Starts serving on a thread of its own: opens the pty (and the log), powers the form on.
/// Callable from anywhere (within a tokio runtime or not); the form runs until the
/// [`Server`] is stopped or dropped.
pub fn serve(config: ServeConfig) -> Result<Server, ServeError> {
    // Refuse a bad fault spec before creating anything (the form is valid by its type).
    config.faults.check(&config.form).map_err(SimError::from)?;
    let (ready, started) = std::sync::mpsc::channel();
    let (stop, stopped) = oneshot::channel();
    let (ending, ended) = oneshot::channel::<()>();
    let thread = std::thread::Builder::new()
        .name("simulated form".into())
        .spawn(move || {
            // Dropped when the thread ends, whichever way: `ended` resolves.
            let _ending = ending;
            let runtime = tokio::runtime::Builder::new_current_thread()
                .enable_all()
                .build()
                .map_err(ServeError::Runtime)?;
            runtime.block_on(run_form(config, ready, stopped))
        })
        .map_err(ServeError::Runtime)?;
    match started.recv() {
        Ok(Started { device, form, bus }) => {
            Ok(Server { device, form, bus, stop: Some(stop), ended, thread: Some(thread) })
        }
        // The thread ended before the form started: its error says why.
        Err(_) => Err(joined(thread).err().unwrap_or_else(|| {
            ServeError::Pty(io::Error::other("the simulator ended before it started"))
        })),
    }
}

/// The form's thread: starts the form, reports it through `ready`, serves until `stop` (or
/// the pty fails), then writes out the log.
async fn run_form(
    config: ServeConfig,
    ready: std::sync::mpsc::Sender<Started>,
    stop: oneshot::Receiver<()>,
) -> Result<(), ServeError> {
    let ServeConfig { form, transport, log: log_path, faults, options } = config;
    let pty = Pty::open().map_err(ServeError::Pty)?;
    let canary = Arc::new(Mutex::new(Canary::open().map_err(ServeError::Pty)?));
    let device = pty.path().to_path_buf();
    let interface = match transport {
        PtyLink::SerialPty => "serial0",
        PtyLink::SlcanPty => "can0",
    };
    let log = match &log_path {
        Some(path) => Some(
            CandumpLog::create(path, interface)
                .map_err(|source| ServeError::Log { path: path.clone(), source })?,
        ),
        None => None,
    };
    match transport {
        PtyLink::SerialPty => {
            let form = SimulatedForm::on_serial(&form, &faults, &options)?;
            let line = SerialLine::new(pty, DEFAULT_BAUD, &faults, log);
            let serving = form.serve_serial(line, options.tick, canary, stop);
            // The caller went away: nothing to serve.
            let Ok(()) = ready.send(Started { device, form, bus: None }) else { return Ok(()) };
            let (line, log) = serving.await;
            line.map_err(ServeError::Pty)?;
            log.map_err(log_error(&log_path))
        }
        PtyLink::SlcanPty => {
            let bus = Arc::new(CanBus::with(CanKind::CLASSIC_1M, &faults, log));
            let form = SimulatedForm::on_can_behind(&form, &bus, &faults, &options, Some(canary))?;
            let adapter = SlcanAdapter::new(pty, &bus);
            let started = Started { device, form, bus: Some(Arc::clone(&bus)) };
            let Ok(()) = ready.send(started) else { return Ok(()) };
            let result = tokio::select! {
                result = adapter.run() => result.map_err(ServeError::Pty),
                _ = stop => Ok(()),
            };
            result.and(bus.flush_log().map_err(log_error(&log_path)))
        }
    }
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
        self.bus.as_deref().map(CanBus::stats)
    }

    /// Serves until `stop` completes (or the pty fails), then stops and writes out the log.
    pub async fn run_until(mut self, stop: impl Future<Output = ()>) -> Result<(), ServeError> {
        tokio::select! {
            _ = &mut self.ended => {}
            () = stop => {}
        }
        self.shutdown()
    }

    /// Stops serving and writes out the log; returns how serving ended. Blocks until the
    /// form's thread has ended (at once, but for writing out the log).
    pub fn shutdown(mut self) -> Result<(), ServeError> {
        self.join()
    }

    fn join(&mut self) -> Result<(), ServeError> {
        if let Some(stop) = self.stop.take() {
            // Gone if the thread already ended.
            let _ = stop.send(());
        }
        self.thread.take().map_or(Ok(()), joined)
    }
}

impl Drop for Server {
    /// Stops serving (the log is written out, errors unreported; use [`Server::shutdown`] to
    /// see them).
    fn drop(&mut self) {
        let _ = self.join();
    }
}

/// Serves `config` until Ctrl-C; `ready` gets the device path once the host can connect.
/// What `dressform sim` calls.
pub fn run_until_ctrl_c(config: ServeConfig, ready: impl FnOnce(&Path)) -> Result<(), ServeError> {
    let server = serve(config)?;
    ready(server.device_path());
    let runtime = tokio::runtime::Builder::new_current_thread()
        .enable_all()
        .build()
        .map_err(ServeError::Runtime)?;
    runtime.block_on(server.run_until(async {
        // Without a signal handler there is nothing to wait for but the pty failing.
        if tokio::signal::ctrl_c().await.is_err() {
            std::future::pending::<()>().await;
        }
    }))
}
