//! A pseudo-terminal pair: the simulator works the master side, the host opens the slave
//! path (`/dev/pts/N`) with a serial-port library exactly as it would a USB adapter.
//!
//! The slave is raw (no echo, no line editing). The simulator keeps a slave descriptor open
//! itself, so the master never sees a hang-up when a host closes the port and reopens it.
//! A host library may mark the terminal exclusive (`TIOCEXCL`, as serialport does by
//! default); on a pty the mark outlives a host that dies without clearing it (killed with
//! Ctrl-C), and every later open by a non-root user fails with `EBUSY`. So the simulator
//! clears the mark from time to time ([`Pty::share`]): the device is not exclusive, but the
//! next host can always open it.
//!
//! **Writes never block the simulator and never tear a message.** What the simulator says is
//! queued whole ([`Pty::queue`]) and written whenever the kernel takes it ([`Pty::flush`]):
//! a host that reads late, or a kernel that holds the pty's bytes for a while (below), loses
//! nothing. Only a queue past [`OUTBOX_LIMIT`] — a reader dead for seconds — loses its
//! oldest whole messages, as a real adapter's buffer overflows; a new session starts with an
//! empty queue ([`Pty::discard_unread`]), and bytes already written stay for the host to
//! read or clear.
//!
//! **The kernel's own stalls.** A pty is not a wire: bytes written to one side reach the other
//! through the kernel's tty flip buffers, pushed by a shared kernel worker. On a loaded machine
//! that worker can hold *every* pty's bytes for hundreds of milliseconds (measured on a 2-core
//! machine running the test suite beside 4 CPU-bound processes: stalls of 150-1300 ms, seen at
//! the same moments by an unrelated pty pair, while a host's `write` slept in the kernel just
//! as long). A simulated node that counted that time as host silence would latch a host
//! timeout that no real wire would cause; a [`Canary`] measures it, so the nodes' watchdogs
//! can leave it out (see `robot::runners`).

use std::collections::VecDeque;
use std::ffi::OsString;
use std::fs::File;
use std::io::{self, Read, Write};
use std::os::fd::OwnedFd;
use std::os::unix::ffi::OsStringExt;
use std::path::{Path, PathBuf};
use std::sync::{Mutex, PoisonError};

use rustix::fs::{Mode, OFlags};
use rustix::pty::OpenptFlags;
use rustix::termios::OptionalActions;
use tokio::io::unix::AsyncFd;
use tokio::time::{Duration, Instant};

/// The most the simulator keeps queued for a host that does not read: a reader this far
/// behind is dead. 256 KiB is over a second of a 1 Mbit/s CAN bus loaded to the full as slcan
/// text (about 8,000 frames/s of at most 27 bytes), and about ten seconds of the reference
/// form's own traffic — many times the longest pty stall measured (1.3 s, module docs).
pub const OUTBOX_LIMIT: usize = 256 * 1024;

/// How often [`Pty::share`] should be called.
pub const SHARE_EVERY: Duration = Duration::from_millis(200);

/// The master side of a pseudo-terminal pair, registered with tokio.
#[derive(Debug)]
pub struct Pty {
    master: AsyncFd<File>,
    slave: OwnedFd,
    path: PathBuf,
    outbox: Mutex<Outbox>,
}

/// Whole messages queued for the host, oldest first; the first may be partly written.
#[derive(Debug, Default)]
struct Outbox {
    messages: VecDeque<Vec<u8>>,
    /// Bytes of the first message already written.
    written: usize,
    /// Bytes queued and not yet written.
    len: usize,
}

impl Outbox {
    fn push(&mut self, bytes: &[u8]) {
        if bytes.is_empty() {
            return;
        }
        self.len += bytes.len();
        self.messages.push_back(bytes.to_vec());
        // Past the limit, drop the oldest messages not begun (a begun one is finished, or
        // the host would see half a message).
        while self.len > OUTBOX_LIMIT {
            let index = usize::from(self.written > 0);
            let Some(dropped) = self.messages.remove(index) else { break };
            self.len -= dropped.len();
        }
    }

    /// The bytes to write next.
    fn next(&self) -> &[u8] {
        self.messages.front().and_then(|m| m.get(self.written..)).unwrap_or_default()
    }

    /// `n` bytes of [`Outbox::next`] were written.
    fn advance(&mut self, n: usize) {
        self.len -= n;
        self.written += n;
        if self.messages.front().is_some_and(|m| self.written >= m.len()) {
            self.messages.pop_front();
            self.written = 0;
        }
    }

    fn clear(&mut self) {
        *self = Self::default();
    }
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
        Ok(Self { master, slave, path, outbox: Mutex::default() })
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

    /// Queues `bytes`, one whole message, for the host (see the module docs); written by
    /// [`Pty::flush`].
    pub fn queue(&self, bytes: &[u8]) {
        self.outbox().push(bytes);
    }

    /// Whether queued bytes wait for [`Pty::flush`].
    pub fn has_unsent(&self) -> bool {
        self.outbox().len > 0
    }

    /// Writes the queued bytes as the kernel takes them; returns once all are written.
    /// Cancel-safe: what was written is off the queue, the rest stays queued.
    pub async fn flush(&self) -> io::Result<()> {
        while self.has_unsent() {
            let mut guard = self.master.writable().await?;
            let written = guard.try_io(|fd| {
                let mut outbox = self.outbox();
                let n = fd.get_ref().write(outbox.next())?;
                outbox.advance(n);
                Ok(n)
            });
            if let Ok(result) = written {
                result?;
            }
        }
        Ok(())
    }

    fn outbox(&self) -> std::sync::MutexGuard<'_, Outbox> {
        self.outbox.lock().unwrap_or_else(PoisonError::into_inner)
    }

    /// Clears an exclusive-use mark a host left on the terminal (see the module docs).
    pub fn share(&self) {
        // Fails only if the descriptor is not a terminal, which it is.
        let _ = rustix::termios::ioctl_tiocnxcl(&self.slave);
    }

    /// Drops what is queued for the host and not yet written (stale answers of a host that
    /// went away), as a real adapter empties its own buffer.
    ///
    /// What the kernel already holds stays: a real adapter cannot take back bytes it sent, and
    /// flushing the terminal's input under a host that is reading races it. pyserial (and so
    /// python-can) reads with `VMIN = 0` after `select`, so bytes flushed between the two make
    /// the read return nothing, which it reports as a disconnected device. Hosts clear their
    /// input when they open the port (pyserial's `open` does; so does dressform's).
    pub fn discard_unread(&self) {
        self.outbox().clear();
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_full_outbox_drops_its_oldest_whole_messages_and_finishes_a_begun_one() {
        let mut outbox = Outbox::default();
        let message = vec![7u8; OUTBOX_LIMIT / 4];
        outbox.push(&message);
        outbox.advance(3);
        for _ in 0..4 {
            outbox.push(&message);
        }
        // One message too many: the oldest not begun went, the begun one stays.
        assert_eq!(outbox.messages.len(), 4);
        assert_eq!(outbox.next().len(), message.len() - 3);
        assert_eq!(outbox.len, OUTBOX_LIMIT - 3);
        outbox.advance(message.len() - 3);
        assert_eq!(outbox.next().len(), message.len());
        assert_eq!(outbox.messages.len(), 3);
    }

    /// A new session drops what is still queued but never what the kernel holds: taking
    /// bytes back under a reading host makes pyserial's read return nothing (see
    /// [`Pty::discard_unread`]).
    #[tokio::test]
    async fn a_new_session_drops_the_queue_and_leaves_the_written_bytes() {
        let pty = Pty::open().unwrap();
        let mut host = std::fs::OpenOptions::new().read(true).open(pty.path()).unwrap();
        pty.queue(b"written\r");
        pty.flush().await.unwrap();
        pty.queue(b"queued\r");
        pty.discard_unread();
        assert!(!pty.has_unsent());
        pty.queue(b"new\r");
        pty.flush().await.unwrap();
        // On a thread, so that a lost byte fails the test rather than hanging it.
        let (sender, received) = std::sync::mpsc::channel();
        std::thread::spawn(move || {
            let mut got = [0u8; 12];
            let _ = sender.send(host.read_exact(&mut got).map(|()| got));
        });
        let got = received.recv_timeout(std::time::Duration::from_secs(10));
        assert_eq!(got.expect("bytes were lost").unwrap(), *b"written\rnew\r");
    }

    /// A host that does not read for longer than the kernel buffers (about 20 KB on Linux)
    /// gets every message later, whole and in order.
    #[tokio::test]
    async fn a_late_reader_loses_nothing() {
        let pty = Pty::open().unwrap();
        let mut host = std::fs::OpenOptions::new().read(true).open(pty.path()).unwrap();
        let messages: Vec<Vec<u8>> = (0..64u8).map(|i| vec![i; 1000]).collect();
        for message in &messages {
            pty.queue(message);
        }
        // The kernel takes part; the rest waits in the queue while the host sleeps.
        let late = tokio::time::timeout(Duration::from_millis(300), pty.flush()).await;
        assert!(late.is_err(), "the kernel took 64 KB for a host that did not read");
        assert!(pty.has_unsent());
        let reader = std::thread::spawn(move || {
            let mut got = vec![0u8; 64_000];
            host.read_exact(&mut got).map(|()| got)
        });
        pty.flush().await.unwrap();
        assert_eq!(reader.join().unwrap().unwrap(), messages.concat());
    }
}
