//! A candump log (`candump -L` format) of the frames a listener on the bus receives.
//!
//! ```text
//! (1700000000.123456) can0 283#010000000F00
//! (1700000000.124001) can0 145##1C409C409C409C409C409C409C409C40
//! (1700000000.125310) can0 20000080#0000000000000000
//! ```
//!
//! One line per frame: the reception time (wall clock seconds, to the microsecond: the wall
//! time when the log was created plus the bus's simulated time since, so it stays exact under
//! tokio's paused clock), the interface name, then `III#DD..` for a classic frame, or
//! `III##FDD..` for a CAN FD frame (`F` = the flags nibble, 1 = bit-rate switch), and
//! `20000080#0000000000000000` for an error frame (CAN_ERR_FLAG | CAN_ERR_BUSERROR).
//! can-utils (`canplayer`, `log2asc`) and python-can's `CanutilsLogReader` read it.
//!
//! Write errors do not stop the simulation: the first one is kept, shown by
//! [`CandumpLog::failure`] as soon as it happens and returned by [`CandumpLog::flush`].

use std::fmt::Write as _;
use std::fs::File;
use std::io::{self, BufWriter, Write};
use std::path::Path;
use std::time::{SystemTime, UNIX_EPOCH};

use embedded_can::Frame as _;
use firmware_protocol::can::Frame;
use tokio::time::{Duration, Instant};

/// How often buffered lines are written out, in simulated time.
const FLUSH_EVERY: Duration = Duration::from_millis(100);

/// A candump log being written.
#[derive(Debug)]
pub struct CandumpLog {
    out: BufWriter<File>,
    interface: String,
    /// Wall clock at `origin`, since the Unix epoch.
    wall_origin: Duration,
    origin: Instant,
    last_flush: Instant,
    error: Option<io::Error>,
}

impl CandumpLog {
    /// Creates (or truncates) the log file; lines name `interface` (e.g. `can0`).
    pub fn create(path: &Path, interface: &str) -> io::Result<Self> {
        let out = BufWriter::new(File::create(path)?);
        let now = Instant::now();
        Ok(Self {
            out,
            interface: interface.to_string(),
            wall_origin: SystemTime::now().duration_since(UNIX_EPOCH).unwrap_or_default(),
            origin: now,
            last_flush: now,
            error: None,
        })
    }

    /// Logs a frame received at `at`.
    pub fn frame(&mut self, at: Instant, frame: &Frame) {
        let line = format_frame(frame);
        self.line(at, &line);
    }

    /// Logs an error frame at `at`.
    pub fn error_frame(&mut self, at: Instant) {
        self.line(at, "20000080#0000000000000000");
    }

    fn line(&mut self, at: Instant, frame: &str) {
        let t = self.wall_origin + at.saturating_duration_since(self.origin);
        let (secs, micros) = (t.as_secs(), t.subsec_micros());
        let result = writeln!(self.out, "({secs}.{micros:06}) {} {frame}", self.interface);
        self.keep(result);
        if at.saturating_duration_since(self.last_flush) >= FLUSH_EVERY {
            self.last_flush = at;
            let result = self.out.flush();
            self.keep(result);
        }
    }

    fn keep(&mut self, result: io::Result<()>) {
        if let Err(error) = result {
            self.error.get_or_insert(error);
        }
    }

    /// The first write error so far, if any (a full disk shows within one flush period).
    pub fn failure(&self) -> Option<String> {
        self.error.as_ref().map(ToString::to_string)
    }

    /// Writes out buffered lines; returns the first write error of the log, if any.
    pub fn flush(&mut self) -> io::Result<()> {
        let result = self.out.flush();
        self.keep(result);
        match self.error.take() {
            Some(error) => Err(error),
            None => Ok(()),
        }
    }
}

/// A frame as candump writes it: `III#DD..`, or `III##1DD..` for CAN FD (with bit-rate
/// switching, as this protocol sends FD frames).
pub fn format_frame(frame: &Frame) -> String {
    let mut text = format!("{:03X}#", frame.standard_id().as_raw());
    if frame.is_fd() {
        text.push_str("#1");
    }
    for byte in frame.data() {
        // Writing to a String cannot fail.
        let _ = write!(text, "{byte:02X}");
    }
    text
}

#[cfg(test)]
mod tests {
    use super::*;
    use firmware_protocol::message::{Positions8, Sync};
    use firmware_protocol::{Message, NodeId, Packet, can};

    #[test]
    fn classic_and_fd_frames_are_written_as_candump_does() {
        let sync = can::encode(&Packet::broadcast(Message::Sync(Sync { duration_ms: 2000 })));
        assert_eq!(format_frame(&sync.unwrap()), "040#D007");
        let node = NodeId::new(5).unwrap();
        let all = can::encode(&Packet::node(node, Message::AllTargets(Positions8::default())));
        assert_eq!(format_frame(&all.unwrap()), format!("145##1{}", "FF".repeat(16)));
    }
}
