//! A pseudo-terminal pair: the simulator works the master side, the host opens the slave
//! path (`/dev/pts/N`) with a serial-port library exactly as it would a USB adapter.
//!
//! The slave is raw (no echo, no line editing). The simulator keeps a slave descriptor open
//! itself, so the master never sees a hang-up when a host closes the port and reopens it.
//! A host library may mark the terminal exclusive (`TIOCEXCL`, as serialport does by
//! default); on a pty the mark outlives a host that dies without clearing it (killed with
//! Ctrl-C), and every later open by a non-root user fails with `EBUSY`. So the simulator
//! clears the mark from time to time ([`Pty::share`]): the device is not exclusive, but the
//! next host can always open it. Writes wait at most [`WRITE_TIMEOUT`] for a host that does
//! not read; then the bytes are dropped.
//!
//! **The kernel's own stalls.** A pty is not a wire: bytes written to one side reach the other
//! through the kernel's tty flip buffers, pushed by a shared kernel worker. On a loaded machine
//! that worker can hold *every* pty's bytes for hundreds of milliseconds (measured on a 2-core
//! machine running the test suite beside 4 CPU-bound processes: stalls of 150-1300 ms, seen at
//! the same moments by an unrelated pty pair, while a host's `write` slept in the kernel just
//! as long). A simulated node that counted that time as host silence would latch a host
//! timeout that no real wire would cause; a [`Canary`] measures it, so the nodes' watchdogs
//! can leave it out (see `robot::runners`).

use std::ffi::OsString;
use std::fs::File;
use std::io::{self, Read, Write};
use std::os::fd::OwnedFd;
use std::os::unix::ffi::OsStringExt;
use std::path::{Path, PathBuf};

use rustix::fs::{Mode, OFlags};
use rustix::pty::OpenptFlags;
use rustix::termios::OptionalActions;
use tokio::io::unix::AsyncFd;
use tokio::time::{Duration, Instant, timeout};

/// How long a write waits for a host that does not read before dropping the bytes.
pub const WRITE_TIMEOUT: Duration = Duration::from_millis(100);

/// How often [`Pty::share`] should be called.
pub const SHARE_EVERY: Duration = Duration::from_millis(200);

/// The master side of a pseudo-terminal pair, registered with tokio.
#[derive(Debug)]
pub struct Pty {
    master: AsyncFd<File>,
    slave: OwnedFd,
    path: PathBuf,
}

/// A new pty pair, both sides non-blocking, the slave raw: `(master, slave, slave path)`.
fn open_pair() -> io::Result<(OwnedFd, OwnedFd, PathBuf)> {
    let master = rustix::pty::openpt(OpenptFlags::RDWR | OpenptFlags::NOCTTY)?;
    rustix::pty::grantpt(&master)?;
    rustix::pty::unlockpt(&master)?;
    let name = rustix::pty::ptsname(&master, Vec::new())?;
    let path = PathBuf::from(OsString::from_vec(name.into_bytes()));
    let slave = rustix::fs::open(
        &path,
        OFlags::RDWR | OFlags::NOCTTY | OFlags::NONBLOCK | OFlags::CLOEXEC,
        Mode::empty(),
    )?;
    let mut termios = rustix::termios::tcgetattr(&slave)?;
    termios.make_raw();
    rustix::termios::tcsetattr(&slave, OptionalActions::Now, &termios)?;
    rustix::io::ioctl_fionbio(&master, true)?;
    Ok((master, slave, path))
}

impl Pty {
    /// Opens a new pair. Must be called within a tokio runtime.
    pub fn open() -> io::Result<Self> {
        let (master, slave, path) = open_pair()?;
        // SAFETY: the `File` owns the master descriptor and lives, unchanged, inside the
        // `AsyncFd` until it is dropped; nothing else closes or replaces it.
        let master = unsafe { AsyncFd::register(File::from(master)) }.map_err(io::Error::from)?;
        Ok(Self { master, slave, path })
    }

    /// The slave path for the host to open.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Reads what the host wrote (at least one byte).
    pub async fn read(&self, buf: &mut [u8]) -> io::Result<usize> {
        loop {
            let mut guard = self.master.readable().await?;
            if let Ok(result) = guard.try_io(|fd| fd.get_ref().read(buf)) {
                return result;
            }
        }
    }

    /// Writes all of `bytes` for the host; gives up (and returns `TimedOut`) if the host does
    /// not read for [`WRITE_TIMEOUT`].
    pub async fn write_all(&self, bytes: &[u8]) -> io::Result<()> {
        let write = async {
            let mut rest = bytes;
            while !rest.is_empty() {
                let mut guard = self.master.writable().await?;
                if let Ok(result) = guard.try_io(|fd| fd.get_ref().write(rest)) {
                    rest = rest.get(result?..).unwrap_or_default();
                }
            }
            Ok(())
        };
        timeout(WRITE_TIMEOUT, write).await.unwrap_or_else(|_| {
            Err(io::Error::new(io::ErrorKind::TimedOut, "the host does not read"))
        })
    }

    /// Clears an exclusive-use mark a host left on the terminal (see the module docs).
    pub fn share(&self) {
        // Fails only if the descriptor is not a terminal, which it is.
        let _ = rustix::termios::ioctl_tiocnxcl(&self.slave);
    }

    /// Drops what was written for the host but not read yet (stale answers of a host that
    /// went away).
    pub fn discard_unread(&self) {
        let _ = rustix::termios::tcflush(&self.slave, rustix::termios::QueueSelector::IFlush);
    }
}

/// A pty pair of the simulator's own that carries one byte at a time, slave to master, to
/// measure how long the kernel holds bytes written to a pty (see the module docs).
#[derive(Debug)]
pub struct Canary {
    master: File,
    slave: File,
    /// When the byte on its way was written (`None`: none is).
    in_flight: Option<Instant>,
}

impl Canary {
    /// Opens its pair (no tokio runtime needed).
    pub fn open() -> io::Result<Self> {
        let (master, slave, _) = open_pair()?;
        Ok(Self { master: File::from(master), slave: File::from(slave), in_flight: None })
    }

    /// How long the byte on its way has been held by the kernel at `now` (zero once it
    /// arrived; then the next one is sent). Never blocks.
    pub fn lag(&mut self, now: Instant) -> Duration {
        let mut buf = [0u8; 16];
        while matches!(self.master.read(&mut buf), Ok(n) if n > 0) {
            self.in_flight = None;
        }
        match self.in_flight {
            Some(sent) => now.saturating_duration_since(sent),
            None => {
                // A failed write (the pair broken) leaves nothing to wait for: no lag.
                if matches!(self.slave.write(&[0]), Ok(1)) {
                    self.in_flight = Some(now);
                }
                Duration::ZERO
            }
        }
    }
}
