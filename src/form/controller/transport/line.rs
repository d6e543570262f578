//! A serial device shared by the serial and slcan links: `serialport` opens it (a USB
//! adapter or a pseudo-terminal alike); a reader thread turns the bytes into packets with the
//! link's parser and hands them to tokio through a channel; writes are small (at most a
//! frame) and go straight to the port through a second handle, which the link's
//! [`Gate`](super::gate::Gate) owns (so an e-stop never waits for the reader).

use std::io::{ErrorKind, Read, Write};
use std::path::Path;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

use firmware_protocol::Packet;
use serialport::ClearBuffer;
use tokio::sync::mpsc;

use super::TransportError;

/// How long a read waits before the reader checks whether it should stop; also the longest a
/// write waits for a device that does not take its bytes.
const READ_TIMEOUT: Duration = Duration::from_millis(10);
/// The most bytes one read takes from the device: at 1 Mbaud about 10 ms of traffic, what
/// arrives within one [`READ_TIMEOUT`].
const READ_CHUNK: usize = 1024;
/// How long a write beside the device's holder ([`Writer::shared`]) keeps trying while the
/// device is busy: the kernel refuses a non-blocking write (`EAGAIN`) while the holder's own
/// write is in progress (the tty's write lock) or while its output buffer is full. The
/// holder's writes are one frame each, so the lock frees within microseconds; a buffer the
/// form has not drained for this long will not take the stop either.
const SHARED_WRITE_PATIENCE: Duration = Duration::from_millis(500);
/// How long a busy shared write waits before it tries again.
const SHARED_WRITE_RETRY: Duration = Duration::from_millis(1);

/// The reading side of an open serial device: its reader thread.
pub struct Line {
    device: String,
    packets: mpsc::UnboundedReceiver<Result<Packet, String>>,
    stop: Arc<AtomicBool>,
    reader: Option<std::thread::JoinHandle<()>>,
}

impl std::fmt::Debug for Line {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Line").field("device", &self.device).finish_non_exhaustive()
    }
}

impl Line {
    /// Opens `path` at `baud` (8N1) and starts reading with `parse`, which turns each chunk
    /// of bytes into the packets it completes; returns the reader and the port to write to.
    pub fn open(
        path: &Path,
        baud: u32,
        mut parse: impl FnMut(&[u8], &mut Vec<Packet>) + Send + 'static,
    ) -> Result<(Self, Writer), TransportError> {
        let device = path.display().to_string();
        let io = |source| TransportError::Io { device: device.clone(), source };
        let writer = serialport::new(device.clone(), baud)
            .timeout(READ_TIMEOUT)
            .open()
            .map_err(|e| io(std::io::Error::from(e)))?;
        // What the device sent before this session (a host that went away left it unread)
        // is not an answer to this one: drop it, as pyserial's `open` does.
        writer.clear(ClearBuffer::Input).map_err(|e| io(std::io::Error::from(e)))?;
        let mut reader = writer.try_clone().map_err(|e| io(std::io::Error::from(e)))?;
        let (tx, packets) = mpsc::unbounded_channel();
        let stop = Arc::new(AtomicBool::new(false));
        let stopping = Arc::clone(&stop);
        let reader = std::thread::Builder::new()
            .name(format!("dressform reader {device}"))
            .spawn(move || {
                let mut buf = [0u8; READ_CHUNK];
                let mut parsed = Vec::new();
                while !stopping.load(Ordering::Relaxed) {
                    match reader.read(&mut buf) {
                        Ok(0) => std::thread::sleep(READ_TIMEOUT),
                        Ok(n) => {
                            parse(&buf[..n], &mut parsed);
                            for packet in parsed.drain(..) {
                                if tx.send(Ok(packet)).is_err() {
                                    return;
                                }
                            }
                        }
                        Err(e)
                            if matches!(
                                e.kind(),
                                ErrorKind::TimedOut
                                    | ErrorKind::Interrupted
                                    | ErrorKind::WouldBlock
                            ) => {}
                        Err(e) => {
                            let _ = tx.send(Err(e.to_string()));
                            return;
                        }
                    }
                }
            })
            .map_err(io)?;
        let line = Self { device: device.clone(), packets, stop, reader: Some(reader) };
        Ok((line, Writer { device, port: Box::new(writer) }))
    }

    /// The device path.
    pub fn device(&self) -> String {
        self.device.clone()
    }

    /// The next packet the reader parsed.
    pub async fn recv(&mut self) -> Result<Packet, TransportError> {
        match self.packets.recv().await {
            Some(Ok(packet)) => Ok(packet),
            Some(Err(message)) => Err(TransportError::Io {
                device: self.device.clone(),
                source: std::io::Error::other(message),
            }),
            None => Err(TransportError::Closed(self.device.clone())),
        }
    }
}

/// The writing handle of an open serial device.
pub struct Writer {
    device: String,
    port: Box<dyn Write + Send>,
}

impl Writer {
    /// Opens `path` for writing beside the process that holds it: no lock taken, none
    /// respected (`flock`), and the terminal's settings left as its holder made them. Only
    /// for an emergency stop whose holder cannot be reached (see
    /// [`super::shared_stop_gate`]). A terminal another process marked exclusive
    /// (`TIOCEXCL`) still refuses a user other than root.
    pub fn shared(path: &Path) -> Result<Self, TransportError> {
        use std::os::unix::fs::OpenOptionsExt;
        let device = path.display().to_string();
        let port = std::fs::OpenOptions::new()
            .write(true)
            // Non-blocking: a device that takes nothing fails the write rather than hang the stop.
            .custom_flags(libc::O_NOCTTY | libc::O_NONBLOCK)
            .open(path)
            .map_err(|source| TransportError::Io { device: device.clone(), source })?;
        Ok(Self { device, port: Box::new(Patient(port)) })
    }

    /// Writes `bytes` in full (each write waits at most [`READ_TIMEOUT`] for the device).
    pub fn write(&mut self, bytes: &[u8]) -> Result<(), TransportError> {
        self.port
            .write_all(bytes)
            .and_then(|()| self.port.flush())
            .map_err(|source| TransportError::Io { device: self.device.clone(), source })
    }

    /// The device path.
    pub fn device(&self) -> &str {
        &self.device
    }
}

/// A non-blocking device written beside its holder: a write the device refuses for now
/// (`EAGAIN`) is tried again for up to [`SHARED_WRITE_PATIENCE`], so an e-stop is not lost to
/// the holder writing at the same instant.
struct Patient(std::fs::File);

impl Write for Patient {
    fn write(&mut self, bytes: &[u8]) -> std::io::Result<usize> {
        let deadline = std::time::Instant::now() + SHARED_WRITE_PATIENCE;
        loop {
            match self.0.write(bytes) {
                Err(e) if e.kind() == ErrorKind::WouldBlock => {
                    if std::time::Instant::now() >= deadline {
                        return Err(std::io::Error::new(
                            ErrorKind::WouldBlock,
                            format!(
                                "the device took nothing for {} ms ({e})",
                                SHARED_WRITE_PATIENCE.as_millis()
                            ),
                        ));
                    }
                    std::thread::sleep(SHARED_WRITE_RETRY);
                }
                done => return done,
            }
        }
    }

    fn flush(&mut self) -> std::io::Result<()> {
        self.0.flush()
    }
}

impl Drop for Line {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Relaxed);
        // The reader's handle closes with it (releasing the port's exclusive lock) within
        // one read timeout; wait, so the port can be opened again at once.
        if let Some(reader) = self.reader.take() {
            let _ = reader.join();
        }
    }
}

#[cfg(test)]
mod tests {
    use std::io::Read;
    use std::os::fd::{FromRawFd, OwnedFd};
    use std::os::unix::fs::OpenOptionsExt;

    use super::*;

    /// A pseudo-terminal's controller side and the path of its device side.
    fn pty() -> (std::fs::File, std::path::PathBuf) {
        // SAFETY: posix_openpt takes flags only and returns a new descriptor or -1.
        let fd = unsafe { libc::posix_openpt(libc::O_RDWR | libc::O_NOCTTY) };
        assert!(fd >= 0, "posix_openpt: {}", std::io::Error::last_os_error());
        // SAFETY: `fd` was just opened above and is owned by nothing else.
        let controller = std::fs::File::from(unsafe { OwnedFd::from_raw_fd(fd) });
        let mut name = [0 as libc::c_char; 128];
        // SAFETY: `fd` is an open pty controller; `name` is writable for its full length.
        unsafe {
            assert_eq!(libc::grantpt(fd), 0);
            assert_eq!(libc::unlockpt(fd), 0);
            assert_eq!(libc::ptsname_r(fd, name.as_mut_ptr(), name.len()), 0);
        }
        // SAFETY: ptsname_r wrote a NUL-terminated path into `name`.
        let path = unsafe { std::ffi::CStr::from_ptr(name.as_ptr()) };
        (controller, path.to_str().unwrap().into())
    }

    #[test]
    fn a_shared_write_waits_out_a_busy_device() {
        let (mut controller, path) = pty();
        let mut writer = Writer::shared(&path).unwrap();
        // Fill the device until it takes nothing more: the form has not drained it.
        let mut filler = std::fs::OpenOptions::new()
            .write(true)
            .custom_flags(libc::O_NOCTTY | libc::O_NONBLOCK)
            .open(&path)
            .unwrap();
        let chunk = [b'x'; 256];
        loop {
            match filler.write(&chunk) {
                Ok(_) => {}
                Err(e) if e.kind() == ErrorKind::WouldBlock => break,
                Err(e) => panic!("filling {}: {e}", path.display()),
            }
        }
        // The form reads again a moment later.
        let reader = std::thread::spawn(move || {
            std::thread::sleep(SHARED_WRITE_PATIENCE / 5);
            let mut buf = [0u8; 4096];
            let mut seen = Vec::new();
            while !seen.ends_with(b"STOP") {
                let n = controller.read(&mut buf).unwrap();
                seen.extend_from_slice(&buf[..n]);
            }
        });
        writer.write(b"STOP").expect("the stop waits for the device to drain");
        reader.join().unwrap();
    }

    #[test]
    fn a_shared_write_gives_up_on_a_device_that_takes_nothing() {
        let (_controller, path) = pty();
        let mut writer = Writer::shared(&path).unwrap();
        let chunk = [b'x'; 256];
        let err = loop {
            if let Err(e) = writer.write(&chunk) {
                break e;
            }
        };
        let patience = format!("took nothing for {} ms", SHARED_WRITE_PATIENCE.as_millis());
        assert!(err.to_string().contains(&patience), "{err}");
    }
}
