//! The local control endpoint: how `dressform estop` reaches the process that owns a link.
//!
//! On a real adapter only one process can open the port, so an e-stop from another terminal
//! cannot use the link itself while a `drive` holds it. Every dressform process that owns a
//! link (`drive`, `run`, `status`, `reset`) therefore listens on a Unix socket named after the
//! device ([`Endpoint`]), in a directory only its user can enter: `$XDG_RUNTIME_DIR/dressform/`,
//! else `<temp dir>/dressform-<uid>/` (mode 0700, checked to be the user's own; the socket is
//! 0600). A client ([`request_estop`]) sends `estop`; the endpoint's own thread — not the
//! owner's runtime, which may be busy — calls [`Gate::emergency_stop`] and answers `stopped
//! <pid>` once the frames are out (or `failed <why>`). The owner's session then ends with
//! "stopped by an e-stop from another terminal".
//!
//! One endpoint per device: binding where a live endpoint answers is refused (two owners of
//! one link is a mistake even on a pseudo-terminal that allows it); a socket left by a
//! process that died is replaced. Symbolic links (`/dev/serial/by-id/...`) resolve to the
//! device they name, so every spelling of one device reaches the same owner.

use std::io::{self, BufRead, BufReader, Read, Write};
use std::os::unix::fs::{DirBuilderExt, MetadataExt, PermissionsExt};
use std::os::unix::net::{UnixListener, UnixStream};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex, PoisonError};
use std::time::Duration;

use super::transport::LinkSpec;
use super::transport::{Gate, StopCause};

/// How long either side waits for the other's line (the owner answers once three frames are
/// written, a few milliseconds).
pub const REPLY_TIMEOUT: Duration = Duration::from_secs(1);

/// The longest request or reply line read.
const MAX_LINE: u64 = 256;

/// The request.
const ESTOP: &str = "estop";

/// How much of a device's name goes into its endpoint's name (a Unix socket's path is at
/// most 107 bytes; the hash keeps names unique).
const MAX_NAME_CHARS: usize = 24;

/// Why the endpoint could not be used.
#[derive(Debug, thiserror::Error)]
pub enum ControlError {
    /// The directory or socket could not be made or used.
    #[error("control endpoint {}: {source}", path.display())]
    Io {
        /// The directory or socket.
        path: PathBuf,
        /// What the operating system said.
        source: io::Error,
    },
    /// The directory is not private to this user (someone else could intercept an e-stop).
    #[error("control endpoint {}: {problem}; remove it or set XDG_RUNTIME_DIR", path.display())]
    Unsafe {
        /// The directory.
        path: PathBuf,
        /// What is wrong with it.
        problem: String,
    },
    /// A live process already owns the link.
    #[error("{device}: another dressform process owns this link (its control endpoint {} answers)", path.display())]
    Owned {
        /// The device.
        device: String,
        /// Its endpoint.
        path: PathBuf,
    },
    /// The owner answered that it could not stop the form, or did not answer in time.
    #[error("{device}: the dressform process that owns this link {problem}")]
    Failed {
        /// The device.
        device: String,
        /// What happened.
        problem: String,
    },
}

/// The directory of the control endpoints: private to this user.
pub fn directory() -> Result<PathBuf, ControlError> {
    let dir = match std::env::var_os("XDG_RUNTIME_DIR").map(PathBuf::from) {
        Some(runtime) if runtime.is_dir() => runtime.join("dressform"),
        _ => std::env::temp_dir().join(format!("dressform-{}", uid())),
    };
    let io = |source| ControlError::Io { path: dir.clone(), source };
    match std::fs::DirBuilder::new().mode(0o700).create(&dir) {
        Ok(()) => {}
        Err(e) if e.kind() == io::ErrorKind::AlreadyExists => {}
        Err(e) => return Err(io(e)),
    }
    let meta = std::fs::symlink_metadata(&dir).map_err(io)?;
    let unsafe_dir =
        |problem: &str| ControlError::Unsafe { path: dir.clone(), problem: problem.into() };
    if !meta.is_dir() {
        return Err(unsafe_dir("not a directory"));
    }
    if meta.uid() != uid() {
        return Err(unsafe_dir("owned by another user"));
    }
    if meta.permissions().mode() & 0o077 != 0 {
        return Err(unsafe_dir("open to other users (it must be mode 0700)"));
    }
    Ok(dir)
}

fn uid() -> u32 {
    // SAFETY: getuid has no preconditions and cannot fail.
    unsafe { libc::getuid() }
}

/// The endpoint's file name for a link: the device's last path component (after resolving
/// symbolic links) and a hash of its full path; `None` for the in-process simulated form,
/// which no other process can reach.
pub fn socket_name(spec: &LinkSpec) -> Option<String> {
    let (kind, name) = match spec {
        LinkSpec::Sim => return None,
        LinkSpec::Serial(path) | LinkSpec::Slcan(path) => {
            let path = std::fs::canonicalize(path).unwrap_or_else(|_| path.clone());
            ("tty", path.display().to_string())
        }
        LinkSpec::Can(interface) => ("can", interface.clone()),
    };
    let last = name.rsplit('/').next().unwrap_or(&name);
    let last: String = last
        .chars()
        .take(MAX_NAME_CHARS)
        .map(|c| if c.is_ascii_alphanumeric() || c == '-' { c } else { '_' })
        .collect();
    Some(format!("{kind}-{last}-{:016x}.sock", fnv1a(name.as_bytes())))
}

/// FNV-1a, 64 bits: a hash that stays the same across Rust versions (std's does not
/// promise to), so every dressform build names a device's endpoint alike.
fn fnv1a(bytes: &[u8]) -> u64 {
    const OFFSET: u64 = 0xcbf2_9ce4_8422_2325;
    const PRIME: u64 = 0x0100_0000_01b3;
    bytes.iter().fold(OFFSET, |h, &b| (h ^ u64::from(b)).wrapping_mul(PRIME))
}

/// The link's gate once it is open; until then, whether an e-stop came meanwhile (it is sent
/// the moment the link opens, before anything else can be).
#[derive(Debug, Default)]
enum Slot {
    #[default]
    Opening,
    StopWhenOpen,
    Open(Gate),
}

/// The endpoint of the process that owns a link, answering e-stops on a thread of its own.
/// Dropping it closes and removes the socket.
#[derive(Debug)]
pub struct Endpoint {
    path: PathBuf,
    gate: Arc<Mutex<Slot>>,
    closing: Arc<AtomicBool>,
    thread: Option<std::thread::JoinHandle<()>>,
}

impl Endpoint {
    /// Binds the endpoint of `spec` before the link is opened (so a second owner is refused
    /// before it writes anything to the device); [`Endpoint::arm`] hands it the link's gate.
    /// `None` for the simulated form.
    pub fn bind(spec: &LinkSpec) -> Result<Option<Self>, ControlError> {
        let Some(name) = socket_name(spec) else { return Ok(None) };
        let path = directory()?.join(name);
        let io = |source| ControlError::Io { path: path.clone(), source };
        if UnixStream::connect(&path).is_ok() {
            return Err(ControlError::Owned { device: device_name(spec), path });
        }
        match std::fs::remove_file(&path) {
            Ok(()) => {}
            Err(e) if e.kind() == io::ErrorKind::NotFound => {}
            Err(e) => return Err(io(e)),
        }
        let listener = UnixListener::bind(&path).map_err(io)?;
        std::fs::set_permissions(&path, std::fs::Permissions::from_mode(0o600)).map_err(io)?;
        let gate: Arc<Mutex<Slot>> = Arc::default();
        let closing = Arc::new(AtomicBool::new(false));
        let thread = {
            let (gate, closing) = (Arc::clone(&gate), Arc::clone(&closing));
            std::thread::Builder::new()
                .name("dressform control endpoint".into())
                .spawn(move || listen(&listener, &gate, &closing))
                .map_err(io)?
        };
        Ok(Some(Self { path, gate, closing, thread: Some(thread) }))
    }

    /// From now on, e-stops go to `gate`; one that came while the link was opening is sent
    /// now, before the caller can send anything.
    pub fn arm(&self, gate: &Gate) -> Result<(), super::transport::TransportError> {
        let mut slot = self.gate.lock().unwrap_or_else(PoisonError::into_inner);
        let pending = matches!(*slot, Slot::StopWhenOpen);
        *slot = Slot::Open(gate.clone());
        if pending { gate.emergency_stop(StopCause::Remote) } else { Ok(()) }
    }

    /// The socket's path.
    pub fn path(&self) -> &Path {
        &self.path
    }
}

impl Drop for Endpoint {
    fn drop(&mut self) {
        self.closing.store(true, Ordering::SeqCst);
        // Wake the accepting thread so it sees `closing`.
        let _ = UnixStream::connect(&self.path);
        if let Some(thread) = self.thread.take() {
            let _ = thread.join();
        }
        let _ = std::fs::remove_file(&self.path);
    }
}

/// Answers requests until `closing`.
fn listen(listener: &UnixListener, gate: &Mutex<Slot>, closing: &AtomicBool) {
    for stream in listener.incoming() {
        if closing.load(Ordering::SeqCst) {
            return;
        }
        // A client that fails mid-request loses its answer; the endpoint goes on.
        if let Ok(stream) = stream {
            let _ = answer(stream, gate);
        }
    }
}

/// Reads one request and answers it.
fn answer(stream: UnixStream, gate: &Mutex<Slot>) -> io::Result<()> {
    stream.set_read_timeout(Some(REPLY_TIMEOUT))?;
    stream.set_write_timeout(Some(REPLY_TIMEOUT))?;
    let mut line = String::new();
    BufReader::new((&stream).take(MAX_LINE)).read_line(&mut line)?;
    let reply = if line.trim() != ESTOP {
        format!("failed to understand the request {:?}", line.trim())
    } else {
        let mut slot = gate.lock().unwrap_or_else(PoisonError::into_inner);
        let sent = match &*slot {
            Slot::Open(gate) => gate.emergency_stop(StopCause::Remote),
            // Nothing can move before the link opens, and then the stop goes first.
            Slot::Opening | Slot::StopWhenOpen => {
                *slot = Slot::StopWhenOpen;
                Ok(())
            }
        };
        match sent {
            Ok(()) => format!("stopped {}", std::process::id()),
            Err(e) => format!("failed to send the emergency stop: {e}"),
        }
    };
    (&stream).write_all(format!("{reply}\n").as_bytes())
}

fn device_name(spec: &LinkSpec) -> String {
    match spec {
        LinkSpec::Sim => "simulated bus".into(),
        LinkSpec::Serial(path) | LinkSpec::Slcan(path) => path.display().to_string(),
        LinkSpec::Can(interface) => interface.clone(),
    }
}

/// Asks the process that owns `spec`'s link to e-stop it. `Ok(Some(pid))`: the owner (that
/// process) sent the emergency stop; `Ok(None)`: no process owns the link through an
/// endpoint (use the link directly).
pub fn request_estop(spec: &LinkSpec) -> Result<Option<u32>, ControlError> {
    let Some(name) = socket_name(spec) else { return Ok(None) };
    let path = directory()?.join(name);
    let Ok(stream) = UnixStream::connect(&path) else { return Ok(None) };
    let failed = |problem: String| ControlError::Failed { device: device_name(spec), problem };
    let talk = || -> io::Result<String> {
        stream.set_read_timeout(Some(REPLY_TIMEOUT))?;
        stream.set_write_timeout(Some(REPLY_TIMEOUT))?;
        (&stream).write_all(format!("{ESTOP}\n").as_bytes())?;
        let mut line = String::new();
        BufReader::new((&stream).take(MAX_LINE)).read_line(&mut line)?;
        Ok(line.trim().to_string())
    };
    let reply = talk().map_err(|e| failed(format!("did not answer: {e}")))?;
    match reply.strip_prefix("stopped ") {
        Some(pid) => Ok(Some(pid.parse().unwrap_or_default())),
        None if reply.is_empty() => Err(failed("closed the connection without an answer".into())),
        None => Err(failed(reply)),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_spelling_of_a_device_names_one_endpoint() {
        let dir = tempfile::tempdir().unwrap();
        let device = dir.path().join("ttyUSB0");
        std::fs::write(&device, b"").unwrap();
        let alias = dir.path().join("usb-FTDI_FT232R-if00-port0");
        std::os::unix::fs::symlink(&device, &alias).unwrap();
        let name = socket_name(&LinkSpec::Serial(device.clone())).unwrap();
        assert!(name.starts_with("tty-ttyUSB0-") && name.ends_with(".sock"), "{name}");
        assert_eq!(socket_name(&LinkSpec::Slcan(alias)), Some(name.clone()));
        let other = socket_name(&LinkSpec::Serial(dir.path().join("ttyUSB1"))).unwrap();
        assert_ne!(other, name);
        assert!(socket_name(&LinkSpec::Can("can0".into())).unwrap().starts_with("can-can0-"));
        assert_eq!(socket_name(&LinkSpec::Sim), None);
        // Unix socket paths are limited to 107 bytes: names stay short.
        let long = LinkSpec::Serial(PathBuf::from(format!("/dev/{}", "x".repeat(300))));
        assert!(socket_name(&long).unwrap().len() <= 4 + MAX_NAME_CHARS + 1 + 16 + 5);
    }
}
