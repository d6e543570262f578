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
use tokio::time::{Duration, timeout};

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

impl Pty {
    /// Opens a new pair. Must be called within a tokio runtime.
    pub fn open() -> io::Result<Self> {
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
