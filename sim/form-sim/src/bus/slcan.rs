//! An slcan (Lawicel ASCII) USB-CAN adapter on a pseudo-terminal, bridging a host to the
//! in-process CAN bus — the protocol of common USB-CAN adapters (CANable, CANtact, USBtin),
//! spoken by python-can's `slcan` interface and by `slcand`.
//!
//! Commands end with `\r` (`\n` is ignored). Answers: `\r` for OK, `\a` (BEL) for an error.
//!
//! | command | meaning | answer |
//! |---|---|---|
//! | `Sn` | bit rate `n`: 0..=8 = 10k, 20k, 50k, 100k, 125k, 250k, 500k, 800k, 1M; 9 = 83.3k | `\r` if it is the bus's rate, else `\a` (a wrong rate cannot reach the bus) |
//! | `O` / `L` | open the channel (`L`: listen only) | `\r`; `\a` if already open or the rate is wrong |
//! | `C` | close the channel | `\r` |
//! | `tIIILDD..` | send a standard frame (3 hex id digits, length 0..=8, data in hex) | `z\r`; `\a` when closed, listen-only or malformed |
//! | `V` / `N` | hardware and firmware version / serial number | `V1013\r` / `NSIM1\r` |
//! | `F` | status flags | `F00\r` |
//! | `Z0` / `Z1` | timestamps off / on | `\r` |
//! | (empty) | — | `\r` |
//!
//! Everything else is answered `\a`: extended (`T`) and remote (`r`, `R`) frames, which this
//! protocol does not use (its nodes would ignore them); CAN FD frames (`d`, `D`, `b`, `B`) and
//! data bit rates (`Yn`), since slcan adapters are classic CAN: behind slcan the form's nodes
//! run a classic bus and the host uses the `Targets` / `Feedback` halves instead of the
//! 16-byte FD messages (as on any classic bus); custom bit timing (`sxxyy`).
//!
//! While the channel is open every frame on the bus is sent to the host as
//! `tIIILDD..\r` (with `Z1`, followed by a 4-hex-digit millisecond timestamp, 0..=59999).
//! Garbage, overlong lines (more than [`MAX_LINE`] bytes) and non-ASCII bytes are answered
//! `\a` and skipped up to the next `\r`.

use std::io;

use firmware_protocol::can::Frame;
use firmware_protocol::slcan;
use tokio::time::{Instant, interval};

use super::can::{CanBus, CanPort};
use super::pty::{Pty, SHARE_EVERY};

/// The longest command line accepted.
pub const MAX_LINE: usize = 64;

/// Bit rates of the `Sn` commands.
const BITRATES: [u32; 10] =
    [10_000, 20_000, 50_000, 100_000, 125_000, 250_000, 500_000, 800_000, 1_000_000, 83_300];

const OK: &[u8] = b"\r";
const ERROR: &[u8] = b"\x07";

/// Whether the adapter is on the bus.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Channel {
    Closed,
    Open,
    ListenOnly,
}

/// An slcan adapter: a pty on one side, a port of the bus on the other.
#[derive(Debug)]
pub struct SlcanAdapter {
    pty: Pty,
    port: CanPort,
    bus_bitrate: u32,
    /// The rate the host asked for (none yet: the bus's).
    bitrate: Option<u32>,
    channel: Channel,
    timestamps: bool,
    origin: Instant,
    line: Vec<u8>,
    /// Skipping an overlong line up to its `\r`.
    skipping: bool,
}

impl SlcanAdapter {
    /// An adapter on `pty`, attached to `bus`.
    pub fn new(pty: Pty, bus: &CanBus) -> Self {
        Self {
            pty,
            port: bus.attach(),
            bus_bitrate: bus.kind().nominal_bitrate(),
            bitrate: None,
            channel: Channel::Closed,
            timestamps: false,
            origin: Instant::now(),
            line: Vec::with_capacity(MAX_LINE),
            skipping: false,
        }
    }

    /// Bridges until the bus closes (or the pty fails).
    pub async fn run(mut self) -> io::Result<()> {
        let mut buf = [0u8; 256];
        let mut share = interval(SHARE_EVERY);
        loop {
            tokio::select! {
                read = self.pty.read(&mut buf) => {
                    let n = read?;
                    let answer = self.take_bytes(&buf[..n]);
                    self.pty.queue(&answer);
                }
                received = self.port.recv_timed() => {
                    let Some(received) = received else { return Ok(()) };
                    if self.channel != Channel::Closed
                        && let Some(line) = self.frame_line(&received.frame, received.at)
                    {
                        self.pty.queue(line.as_bytes());
                    }
                }
                written = self.pty.flush(), if self.pty.has_unsent() => written?,
                _ = share.tick() => self.pty.share(),
            }
        }
    }

    /// Takes bytes from the host; returns the answers to the commands they complete.
    fn take_bytes(&mut self, bytes: &[u8]) -> Vec<u8> {
        let mut answer = Vec::new();
        for &byte in bytes {
            match byte {
                b'\r' => {
                    let line = std::mem::take(&mut self.line);
                    if std::mem::take(&mut self.skipping) {
                        answer.extend_from_slice(ERROR);
                    } else {
                        answer.extend_from_slice(&self.command(&line));
                    }
                }
                b'\n' => {}
                _ if self.skipping => {}
                _ if self.line.len() == MAX_LINE => {
                    self.line.clear();
                    self.skipping = true;
                }
                _ => self.line.push(byte),
            }
        }
        answer
    }

    /// Executes one command line (without its `\r`).
    fn command(&mut self, line: &[u8]) -> Vec<u8> {
        let Ok(line) = std::str::from_utf8(line) else { return ERROR.to_vec() };
        let mut chars = line.chars();
        let (command, args) = (chars.next(), chars.as_str());
        let ok = match (command, args) {
            (None, _) => true,
            (Some('S'), rate) => self.set_bitrate(rate),
            (Some('O'), "") => self.open(Channel::Open),
            (Some('L'), "") => self.open(Channel::ListenOnly),
            (Some('C'), "") => {
                self.channel = Channel::Closed;
                true
            }
            (Some('t'), _) if self.channel == Channel::Open => {
                // A host sends no timestamps: a line with one is malformed.
                let frame =
                    slcan::parse(line.as_bytes()).and_then(|(f, at)| at.is_none().then_some(f));
                return match frame.and_then(|f| self.port.queue(f).ok()) {
                    Some(()) => b"z\r".to_vec(),
                    None => ERROR.to_vec(),
                };
            }
            (Some('V'), "") => return b"V1013\r".to_vec(),
            (Some('N'), "") => return b"NSIM1\r".to_vec(),
            (Some('F'), "") => return b"F00\r".to_vec(),
            (Some('Z'), "0" | "1") => {
                self.timestamps = args == "1";
                true
            }
            _ => false,
        };
        if ok { OK.to_vec() } else { ERROR.to_vec() }
    }

    fn set_bitrate(&mut self, code: &str) -> bool {
        let rate = code.parse::<usize>().ok().and_then(|i| BITRATES.get(i)).copied();
        match rate {
            Some(rate) if self.channel == Channel::Closed => {
                self.bitrate = Some(rate);
                rate == self.bus_bitrate
            }
            _ => false,
        }
    }

    fn open(&mut self, channel: Channel) -> bool {
        let rate_ok = self.bitrate.is_none_or(|rate| rate == self.bus_bitrate);
        if self.channel != Channel::Closed || !rate_ok {
            return false;
        }
        // A new session: drop what an earlier host left unread.
        self.pty.discard_unread();
        self.channel = channel;
        true
    }

    /// `tIIILDD..[TTTT]\r` for a classic frame received at `at`.
    fn frame_line(&self, frame: &Frame, at: Instant) -> Option<slcan::Line> {
        let ms = at.saturating_duration_since(self.origin).as_millis() % 60_000;
        // Below 60000, so it fits.
        slcan::format(frame, self.timestamps.then_some(ms as u16))
    }
}
