//! A serial line over a pseudo-terminal, with the protocol's serial mapping (COBS frames,
//! CRC, sequence numbers).
//!
//! The host writes requests to the slave side; [`SerialLine::next_request`] decodes them
//! from the master side, dropping garbage and bad frames (the decoder resynchronises at the
//! next `0x00`). Answers go back with [`SerialLine::send`], which encodes them with the
//! request's sequence number and writes them as a line at `baud` would carry them: back to
//! back, after the bytes before them, and no earlier than the wire time of the answer (from
//! [`budget::Bus::frame_time_ns`]) — so latency is realistic, to tokio's millisecond timer.
//! The line is half-duplex and the host is the master, so answers never overlap.
//!
//! **Faults** ([`crate::fault`]) apply per frame, both ways: a dropped or bus-off frame is
//! lost; a corrupted request fails its CRC at the nodes (it is lost too), a corrupted answer
//! reaches the host with one bit flipped; `delay` holds every frame back.
//!
//! **Log**: requests are logged when they arrive, answers when they are written, as the CAN
//! frames of the same packets (the serial header and CRC are not logged); a corrupted answer
//! is logged as an error frame.

use std::collections::VecDeque;
use std::io;

use firmware_protocol::{Packet, budget, can, serial};
use tokio::time::{Duration, Instant, sleep_until};

use super::candump::CandumpLog;
use super::pty::{Pty, SHARE_EVERY};
use crate::fault::{BusFaultInjector, FaultSpec, FrameFault};

/// The protocol's serial baud rate.
pub const DEFAULT_BAUD: u32 = 1_000_000;

/// Bytes to write at an instant.
#[derive(Debug)]
struct Answer {
    due: Instant,
    bytes: Vec<u8>,
    /// What to log: a frame, or an error frame (`None`).
    log: Vec<Option<can::Frame>>,
}

/// The simulator's end of a serial line.
#[derive(Debug)]
pub struct SerialLine {
    pty: Pty,
    baud: u32,
    origin: Instant,
    decoder: serial::Decoder,
    /// Requests decoded and waiting for their delay.
    requests: VecDeque<(Instant, serial::Frame)>,
    answers: VecDeque<Answer>,
    /// When the line is free for the next answer.
    free_at: Instant,
    faults: BusFaultInjector,
    log: Option<CandumpLog>,
    next_share: Instant,
}

impl SerialLine {
    /// A line on `pty` at `baud`, with the bus faults of `faults` timed from now.
    pub fn new(pty: Pty, baud: u32, faults: &FaultSpec, log: Option<CandumpLog>) -> Self {
        let now = Instant::now();
        Self {
            pty,
            baud: baud.max(1),
            origin: now,
            decoder: serial::Decoder::new(),
            requests: VecDeque::new(),
            answers: VecDeque::new(),
            free_at: now,
            faults: BusFaultInjector::new(faults),
            log,
            next_share: now,
        }
    }

    /// The next request from the host, or `None` at `until`. Meanwhile writes the answers
    /// that are due.
    pub async fn next_request(&mut self, until: Instant) -> io::Result<Option<serial::Frame>> {
        let mut buf = [0u8; 256];
        loop {
            let now = Instant::now();
            if self.requests.front().is_some_and(|(due, _)| *due <= now) {
                return Ok(self.requests.pop_front().map(|(_, frame)| frame));
            }
            if now >= self.next_share {
                self.pty.share();
                self.next_share = now + SHARE_EVERY;
            }
            self.queue_due(now);
            if now >= until {
                return Ok(None);
            }
            let next = [self.requests.front().map(|r| r.0), self.answers.front().map(|a| a.due)]
                .into_iter()
                .flatten()
                .fold(until.min(self.next_share), Instant::min);
            tokio::select! {
                read = self.pty.read(&mut buf) => {
                    let n = read?;
                    self.take_bytes(&buf[..n]);
                }
                written = self.pty.flush(), if self.pty.has_unsent() => written?,
                () = sleep_until(next) => {}
            }
        }
    }

    /// Decodes bytes from the host; valid frames become requests (unless a fault loses them).
    fn take_bytes(&mut self, bytes: &[u8]) {
        let now = Instant::now();
        let frames: Vec<serial::Frame> = self.decoder.feed(bytes).filter_map(Result::ok).collect();
        for frame in frames {
            let len = frame.packet.message.code().payload_len();
            if self.is_bus_off(now) {
                continue;
            }
            match self.faults.draw(8 * serial::frame_len(len)) {
                FrameFault::None => {}
                FrameFault::Dropped | FrameFault::Corrupted { .. } => continue,
            }
            if let (Some(log), Ok(can)) = (self.log.as_mut(), can::encode(&frame.packet)) {
                log.frame(now, &can);
            }
            self.requests.push_back((now + self.faults.delay(), frame));
        }
    }

    fn is_bus_off(&self, at: Instant) -> bool {
        self.faults.is_bus_off(at.saturating_duration_since(self.origin))
    }

    /// Schedules `packets`, the answer to the request numbered `seq`, to be written `delay`
    /// from now (plus the line's own delay and wire time).
    pub fn send(&mut self, seq: u8, packets: &[Packet], delay: Duration) {
        if packets.is_empty() {
            return;
        }
        let now = Instant::now();
        let line = budget::Bus::Serial { baud: self.baud };
        let mut bytes = Vec::new();
        let mut log = Vec::new();
        let mut wire = Duration::ZERO;
        for &packet in packets {
            let Ok(encoded) = serial::encode(&serial::Frame { seq, packet }) else { continue };
            let len = packet.message.code().payload_len();
            wire += Duration::from_nanos(line.frame_time_ns(len));
            if self.is_bus_off(now) {
                continue;
            }
            match self.faults.draw(8 * encoded.len()) {
                FrameFault::Dropped => continue,
                FrameFault::Corrupted { bit } => {
                    let mut encoded = encoded;
                    if let Some(byte) = encoded.get_mut(bit / 8) {
                        *byte ^= 1 << (bit % 8);
                    }
                    bytes.extend_from_slice(&encoded);
                    log.push(None);
                }
                FrameFault::None => {
                    bytes.extend_from_slice(&encoded);
                    log.push(can::encode(&packet).ok());
                }
            }
        }
        let due = (now + delay + self.faults.delay()).max(self.free_at) + wire;
        self.free_at = due;
        self.answers.push_back(Answer { due, bytes, log });
    }

    /// Queues every answer due by `now` for the host (see [`Pty::queue`]).
    fn queue_due(&mut self, now: Instant) {
        while self.answers.front().is_some_and(|a| a.due <= now) {
            let Some(answer) = self.answers.pop_front() else { break };
            if let Some(log) = self.log.as_mut() {
                for frame in &answer.log {
                    match frame {
                        Some(frame) => log.frame(answer.due, frame),
                        None => log.error_frame(answer.due),
                    }
                }
            }
            self.pty.queue(&answer.bytes);
        }
    }

    /// Writes out the log, if any; returns its first write error.
    pub fn flush_log(&mut self) -> io::Result<()> {
        self.log.as_mut().map_or(Ok(()), CandumpLog::flush)
    }
}
