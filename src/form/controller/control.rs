//! The local control endpoint: how `dressform estop` reaches the process that owns a link.
//!
//! On a real adapter only one process can open the port, so an e-stop from another terminal
//! cannot use the link itself while a `drive` holds it. Every dressform process that owns a
//! link (`drive`, `run`, `demo`, `status`, `reset`) therefore listens on a local socket named
//! after the device ([`Endpoint`]); a client ([`request_estop`]) sends `estop`, and a thread
//! of the endpoint's — not the owner's runtime, which may be busy — calls
//! [`Gate::emergency_stop`] and answers `stopped <pid>` once the frames are out (or
//! `failed <why>`). The owner's session then ends with "stopped by an e-stop from another
//! terminal".
//!
//! **Where it is.** A Linux *abstract* Unix socket (no file; it vanishes with its process)
//! named after the device's canonical path: `dressform/estop/tty/dev/pts/5`,
//! `dressform/estop/can/can0` (a long path is shortened with a hash, [`socket_name`]). The
//! name depends on nothing but the device: not on `XDG_RUNTIME_DIR`, `TMPDIR` or a folder
//! another user may have made, and no socket is ever left behind by a process that died.
//! Symbolic links (`/dev/serial/by-id/...`) resolve to the device they name, so every
//! spelling of one device reaches the same owner. Abstract sockets are per network
//! namespace: a process in another one (a container) does not see the endpoint, and
//! `estop` then sends the stop on the link itself.
//!
//! **Who answers.** Anyone may ask for a stop (a stop is never refused). The client checks
//! who answered (the socket's peer credentials, [`Owner`]): an answer from a process of
//! another user (not root) could come from a process squatting the name, so `estop` then
//! also sends the stop on the link itself.
//!
//! **Never held up.** The endpoint accepts in a loop and answers every client on a thread of
//! its own, so silent or slow clients cannot delay another client's stop.
//!
//! One endpoint per device: binding where one is bound is refused (two owners of one link is
//! a mistake even on a pseudo-terminal that allows it).
//!
//! Beside it, [`emergency_stop`]: the same stop from this process, on a link it opened itself.

use std::io::{self, BufRead, BufReader, Read, Write};
use std::os::fd::AsRawFd;
use std::os::linux::net::SocketAddrExt;
use std::os::unix::net::{SocketAddr, UnixListener, UnixStream};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Condvar, Mutex, PoisonError};
use std::time::Duration;

use super::transport::LinkSpec;
use super::transport::{Gate, StopCause, Transport, TransportError};

/// How long the endpoint waits for a client's request line, and for the client to take its
/// answer.
pub const REPLY_TIMEOUT: Duration = Duration::from_secs(1);

/// How long a client waits for the owner's answer before it sends the stop on the link as
/// well: the owner answers once three frames are written, a few milliseconds (at most 24 ms
/// measured on a loaded machine, docs/performance.md#e-stop-latency); an owner that takes longer is
/// hung or descheduled, and a stop sent twice does no harm.
pub const OWNER_ANSWER_WAIT: Duration = Duration::from_millis(250);

/// The longest request or reply line read.
const MAX_LINE: u64 = 256;

/// The request.
const ESTOP: &str = "estop";

/// Every endpoint's name starts so.
const PREFIX: &str = "dressform/estop/";

/// The longest abstract socket name (a socket address holds 108 bytes, the first of an
/// abstract name is its leading NUL).
const MAX_NAME_BYTES: usize = 107;

/// How much of a long device path is kept beside its hash.
const KEPT_PATH_CHARS: usize = 40;

/// The stack of a thread answering one client: it reads a line and writes one.
const ANSWER_STACK_BYTES: usize = 64 * 1024;

/// Why the endpoint could not be used.
#[derive(Debug, thiserror::Error)]
pub enum ControlError {
    /// The socket could not be made or used.
    #[error("control endpoint of {device}: {source}")]
    Io {
        /// The device.
        device: String,
        /// What the operating system said.
        source: io::Error,
    },
    /// A live process already owns the link.
    #[error("{device}: another process (pid {pid}) owns this link: its control endpoint answers")]
    Owned {
        /// The device.
        device: String,
        /// The owner's process id (0 when the system did not say).
        pid: u32,
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

/// The process that answered an e-stop request.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Owner {
    /// Its process id.
    pub pid: u32,
    /// Its user id.
    pub uid: u32,
}

impl Owner {
    /// Whether its answer can be believed: a process of this user or of root. Another user's
    /// process may have taken the device's name without owning the device.
    pub fn trusted(&self) -> bool {
        self.uid == uid() || self.uid == 0
    }
}

fn uid() -> u32 {
    // SAFETY: getuid has no preconditions and cannot fail.
    unsafe { libc::getuid() }
}

/// The endpoint's abstract socket name for a link: [`PREFIX`], the link's kind and the
/// device's canonical path (symbolic links resolved); a path too long for a socket name keeps
/// its last characters beside a hash of the whole. `None` for the in-process simulated form,
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
    let whole = format!("{PREFIX}{kind}{name}");
    if whole.len() <= MAX_NAME_BYTES {
        return Some(whole);
    }
    let chars: Vec<char> = name.chars().collect();
    let tail: String = chars[chars.len().saturating_sub(KEPT_PATH_CHARS)..].iter().collect();
    Some(format!("{PREFIX}{kind}#{:016x}…{tail}", fnv1a(name.as_bytes())))
}

/// FNV-1a, 64 bits: a hash that stays the same across Rust versions (std's does not
/// promise to), so every dressform build names a device's endpoint alike.
fn fnv1a(bytes: &[u8]) -> u64 {
    const OFFSET: u64 = 0xcbf2_9ce4_8422_2325;
    const PRIME: u64 = 0x0100_0000_01b3;
    bytes.iter().fold(OFFSET, |h, &b| (h ^ u64::from(b)).wrapping_mul(PRIME))
}

fn address(name: &str) -> io::Result<SocketAddr> {
    SocketAddr::from_abstract_name(name.as_bytes())
}

/// The process at the other end of a Unix socket.
fn peer(stream: &UnixStream) -> io::Result<Owner> {
    let mut cred = libc::ucred { pid: 0, uid: 0, gid: 0 };
    let mut len = std::mem::size_of::<libc::ucred>() as libc::socklen_t;
    // SAFETY: `cred` and `len` are valid for writes and `len` holds `cred`'s size, as
    // getsockopt(SO_PEERCRED) requires; the descriptor is a Unix socket owned by `stream`.
    let status = unsafe {
        libc::getsockopt(
            stream.as_raw_fd(),
            libc::SOL_SOCKET,
            libc::SO_PEERCRED,
            (&raw mut cred).cast(),
            &raw mut len,
        )
    };
    if status != 0 {
        return Err(io::Error::last_os_error());
    }
    Ok(Owner { pid: u32::try_from(cred.pid).unwrap_or_default(), uid: cred.uid })
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

/// How many clients are being answered a stop: from the moment a client's request is read
/// to the moment its answer is written. The stop itself ends the owner's command at once, so
/// the owner waits for these answers before it closes the endpoint; a client that gets none
/// would send the stop again on the link, beside its owner.
#[derive(Debug, Default)]
struct Answering {
    count: Mutex<usize>,
    done: Condvar,
}

impl Answering {
    fn start(&self) {
        *self.count.lock().unwrap_or_else(PoisonError::into_inner) += 1;
    }

    fn end(&self) {
        let mut count = self.count.lock().unwrap_or_else(PoisonError::into_inner);
        *count = count.saturating_sub(1);
        self.done.notify_all();
    }

    /// Waits until no answer is pending, at most `timeout`.
    fn wait(&self, timeout: Duration) {
        let count = self.count.lock().unwrap_or_else(PoisonError::into_inner);
        let _ = self.done.wait_timeout_while(count, timeout, |c| *c > 0);
    }
}

/// The endpoint of the process that owns a link, answering e-stops on threads of its own.
/// Dropping it waits for the answers being written (at most [`REPLY_TIMEOUT`]), then closes
/// the socket.
#[derive(Debug)]
pub struct Endpoint {
    name: String,
    gate: Arc<Mutex<Slot>>,
    answering: Arc<Answering>,
    closing: Arc<AtomicBool>,
    thread: Option<std::thread::JoinHandle<()>>,
}

impl Endpoint {
    /// Binds the endpoint of `spec` before the link is opened (so a second owner is refused
    /// before it writes anything to the device); [`Endpoint::arm`] hands it the link's gate.
    /// `None` for the simulated form.
    pub fn bind(spec: &LinkSpec) -> Result<Option<Self>, ControlError> {
        let Some(name) = socket_name(spec) else { return Ok(None) };
        let io = |source| ControlError::Io { device: device_name(spec), source };
        let listener = match UnixListener::bind_addr(&address(&name).map_err(io)?) {
            Ok(listener) => listener,
            Err(e) if e.kind() == io::ErrorKind::AddrInUse => {
                let pid = UnixStream::connect_addr(&address(&name).map_err(io)?)
                    .and_then(|s| peer(&s))
                    .map_or(0, |owner| owner.pid);
                return Err(ControlError::Owned { device: device_name(spec), pid });
            }
            Err(e) => return Err(io(e)),
        };
        let gate: Arc<Mutex<Slot>> = Arc::default();
        let answering: Arc<Answering> = Arc::default();
        let closing = Arc::new(AtomicBool::new(false));
        let thread = {
            let (gate, answering, closing) =
                (Arc::clone(&gate), Arc::clone(&answering), Arc::clone(&closing));
            std::thread::Builder::new()
                .name("dressform control endpoint".into())
                .spawn(move || listen(&listener, &gate, &answering, &closing))
                .map_err(io)?
        };
        Ok(Some(Self { name, gate, answering, closing, thread: Some(thread) }))
    }

    /// From now on, e-stops go to `gate`; one that came while the link was opening is sent
    /// now, before the caller can send anything.
    pub fn arm(&self, gate: &Gate) -> Result<(), TransportError> {
        let mut slot = self.gate.lock().unwrap_or_else(PoisonError::into_inner);
        let pending = matches!(*slot, Slot::StopWhenOpen);
        *slot = Slot::Open(gate.clone());
        if pending { gate.emergency_stop(StopCause::Remote) } else { Ok(()) }
    }

    /// The socket's abstract name.
    pub fn name(&self) -> &str {
        &self.name
    }
}

impl Drop for Endpoint {
    fn drop(&mut self) {
        self.answering.wait(REPLY_TIMEOUT);
        self.closing.store(true, Ordering::SeqCst);
        // Wake the accepting thread so it sees `closing`.
        if let Ok(address) = address(&self.name) {
            let _ = UnixStream::connect_addr(&address);
        }
        if let Some(thread) = self.thread.take() {
            let _ = thread.join();
        }
    }
}

/// Accepts clients until `closing`, each answered on a thread of its own.
fn listen(
    listener: &UnixListener,
    gate: &Arc<Mutex<Slot>>,
    answering: &Arc<Answering>,
    closing: &AtomicBool,
) {
    for stream in listener.incoming() {
        if closing.load(Ordering::SeqCst) {
            return;
        }
        // A client that fails mid-request loses its answer; the endpoint goes on.
        let Ok(stream) = stream else { continue };
        let (gate, answering) = (Arc::clone(gate), Arc::clone(answering));
        let spawned = std::thread::Builder::new()
            .name("dressform control client".into())
            .stack_size(ANSWER_STACK_BYTES)
            .spawn(move || {
                let _ = answer(stream, &gate, &answering);
            });
        // Out of threads: that client gets no answer (it then sends the stop on the link).
        drop(spawned);
    }
}

/// Reads one request and answers it (counted in `answering` from the request's reading to
/// the answer's writing).
fn answer(stream: UnixStream, gate: &Mutex<Slot>, answering: &Answering) -> io::Result<()> {
    stream.set_read_timeout(Some(REPLY_TIMEOUT))?;
    stream.set_write_timeout(Some(REPLY_TIMEOUT))?;
    let mut line = String::new();
    BufReader::new((&stream).take(MAX_LINE)).read_line(&mut line)?;
    answering.start();
    let written = reply(&stream, &line, gate);
    answering.end();
    written
}

/// Carries out one request line and writes the answer.
fn reply(stream: &UnixStream, line: &str, gate: &Mutex<Slot>) -> io::Result<()> {
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
    (&*stream).write_all(format!("{reply}\n").as_bytes())
}

fn device_name(spec: &LinkSpec) -> String {
    match spec {
        LinkSpec::Sim => "simulated bus".into(),
        LinkSpec::Serial(path) | LinkSpec::Slcan(path) => path.display().to_string(),
        LinkSpec::Can(interface) => interface.clone(),
    }
}

/// Asks the process that owns `spec`'s link to e-stop it. `Ok(Some(owner))`: that process
/// answered that it sent the emergency stop (check [`Owner::trusted`]); `Ok(None)`: no
/// process owns the link through an endpoint (use the link directly).
pub fn request_estop(spec: &LinkSpec) -> Result<Option<Owner>, ControlError> {
    let Some(name) = socket_name(spec) else { return Ok(None) };
    let device = device_name(spec);
    let address = address(&name).map_err(|source| ControlError::Io { device, source })?;
    let Ok(stream) = UnixStream::connect_addr(&address) else { return Ok(None) };
    let failed = |problem: String| ControlError::Failed { device: device_name(spec), problem };
    let owner = peer(&stream).map_err(|e| failed(format!("cannot be identified: {e}")))?;
    let talk = || -> io::Result<String> {
        stream.set_read_timeout(Some(OWNER_ANSWER_WAIT))?;
        stream.set_write_timeout(Some(OWNER_ANSWER_WAIT))?;
        (&stream).write_all(format!("{ESTOP}\n").as_bytes())?;
        let mut line = String::new();
        BufReader::new((&stream).take(MAX_LINE)).read_line(&mut line)?;
        Ok(line.trim().to_string())
    };
    let reply = talk().map_err(|e| failed(format!("(pid {}) did not answer: {e}", owner.pid)))?;
    match reply.strip_prefix("stopped ") {
        Some(_) => Ok(Some(owner)),
        None if reply.is_empty() => {
            Err(failed(format!("(pid {}) closed the connection without an answer", owner.pid)))
        }
        None => Err(failed(format!("(pid {}) {reply}", owner.pid))),
    }
}

/// Broadcasts an emergency stop on a link this process opened (see [`Gate`]): every
/// node stops, powers off and latches `EMERGENCY_STOP` until a FaultReset.
pub fn emergency_stop<T: Transport>(transport: &T) -> Result<(), TransportError> {
    transport.gate().emergency_stop(StopCause::Requested)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::PathBuf;

    #[test]
    fn every_spelling_of_a_device_names_one_endpoint() {
        let dir = tempfile::tempdir().unwrap();
        let device = dir.path().join("ttyUSB0");
        std::fs::write(&device, b"").unwrap();
        let alias = dir.path().join("usb-FTDI_FT232R-if00-port0");
        std::os::unix::fs::symlink(&device, &alias).unwrap();
        let name = socket_name(&LinkSpec::Serial(device.clone())).unwrap();
        assert!(name.starts_with("dressform/estop/tty/") && name.ends_with("/ttyUSB0"), "{name}");
        assert_eq!(socket_name(&LinkSpec::Slcan(alias)), Some(name.clone()));
        let other = socket_name(&LinkSpec::Serial(dir.path().join("ttyUSB1"))).unwrap();
        assert_ne!(other, name);
        assert_eq!(socket_name(&LinkSpec::Can("can0".into())).unwrap(), "dressform/estop/cancan0");
        assert_eq!(socket_name(&LinkSpec::Sim), None);
        // Socket names are limited to 107 bytes: long paths are shortened, still unique.
        let long = |c: &str| LinkSpec::Serial(PathBuf::from(format!("/dev/{}", c.repeat(300))));
        let (x, y) = (socket_name(&long("x")).unwrap(), socket_name(&long("y")).unwrap());
        assert!(x.len() <= MAX_NAME_BYTES && y.len() <= MAX_NAME_BYTES, "{x}");
        assert_ne!(x, y);
    }

    #[test]
    fn silent_clients_do_not_hold_up_a_stop() {
        let spec = LinkSpec::Can(format!("test-silent-{}", std::process::id()));
        let endpoint = Endpoint::bind(&spec).unwrap().unwrap();
        let address = address(endpoint.name()).unwrap();
        // Five clients that connect and say nothing.
        let silent: Vec<UnixStream> =
            (0..5).map(|_| UnixStream::connect_addr(&address).unwrap()).collect();
        let start = std::time::Instant::now();
        let owner = request_estop(&spec).unwrap().unwrap();
        // Far below the 1 s a client may take to speak (the old one-at-a-time endpoint waited
        // that long for each silent client before it read this request).
        assert!(start.elapsed() < REPLY_TIMEOUT / 2, "{:?}", start.elapsed());
        assert_eq!(owner.pid, std::process::id());
        assert!(owner.trusted());
        drop(silent);
        // A second owner of the same link is refused while the first lives.
        let refused = Endpoint::bind(&spec).unwrap_err();
        assert!(refused.to_string().contains("owns this link"), "{refused}");
        drop(endpoint);
        assert!(request_estop(&spec).unwrap().is_none());
        assert!(Endpoint::bind(&spec).unwrap().is_some());
    }
}
