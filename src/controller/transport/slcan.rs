//! slcan (Lawicel ASCII) USB-CAN adapters on a serial port: CANable, CANtact, USBtin, and
//! the simulated adapter of `dressform sim --slcan-pty`.
//!
//! Opening sends `C` (close), `S8` (1 Mbit/s) and `O` (open). A frame goes out as
//! `tIIILDD..\r` (standard id, length, data in hex); received lines `tIIILDD..` (with or
//! without a 4-digit timestamp) are frames, everything else (`\r` and `z\r` acknowledgements,
//! `\a` errors — python-can's adapter sends no acks at all) is skipped.
//!
//! slcan adapters are classic CAN, so the link is [`Link::ClassicCan`]: the host sends
//! `Targets` halves, never the 16-byte `AllTargets` (refused with
//! [`TransportError::Unsupported`] if asked); a CAN FD form needs SocketCAN with an FD
//! interface.

use std::path::Path;

use firmware_protocol::{Link, Packet, can};

use super::line::{Line, Writer};
use super::{Transport, TransportError};
use crate::controller::estop::{Gate, PacketSink};

/// The longest line kept while parsing (a frame line is at most 26 characters).
const MAX_LINE: usize = 64;

/// The adapter's serial speed (ignored by USB adapters and ptys; the usual setting).
const BAUD: u32 = 115_200;

/// An slcan adapter.
#[derive(Debug)]
pub struct Slcan {
    line: Line,
    gate: Gate,
}

/// The writing side: one text line per frame.
struct Lines(Writer);

impl PacketSink for Lines {
    fn write(&mut self, packet: &Packet) -> Result<(), TransportError> {
        let unsupported = |what: &str| TransportError::Unsupported {
            device: self.0.device().to_string(),
            what: format!("{} ({what})", packet.message.code().name()),
        };
        let frame = can::encode(packet).map_err(|e| unsupported(&e.to_string()))?;
        let text = format_frame(&frame).ok_or_else(|| unsupported("not a classic CAN frame"))?;
        self.0.write(text.as_bytes())
    }
}

impl Slcan {
    /// Opens the adapter's port and its channel at 1 Mbit/s.
    pub fn open(path: &Path) -> Result<Self, TransportError> {
        let mut text = Vec::new();
        let (line, mut writer) = Line::open(path, BAUD, move |bytes, out| {
            for &byte in bytes {
                match byte {
                    b'\r' | b'\x07' => {
                        out.extend(parse_line(&text));
                        text.clear();
                    }
                    b'\n' => {}
                    _ if text.len() < MAX_LINE => text.push(byte),
                    _ => {}
                }
            }
        })?;
        writer.write(b"C\rS8\rO\r")?;
        let gate = Gate::new(line.device(), Lines(writer));
        Ok(Self { line, gate })
    }
}

/// The slcan text of a classic frame: `tIIILDD..\r`.
pub fn format_frame(frame: &can::Frame) -> Option<String> {
    use embedded_can::Frame as _;
    let embedded_can::Id::Standard(id) = frame.id() else { return None };
    if frame.is_fd() || frame.data().len() > 8 {
        return None;
    }
    let mut text = format!("t{:03X}{}", id.as_raw(), frame.data().len());
    for byte in frame.data() {
        text.push_str(&format!("{byte:02X}"));
    }
    text.push('\r');
    Some(text)
}

/// The packet of a received line, if it is a valid protocol frame.
pub fn parse_line(line: &[u8]) -> Option<Packet> {
    use embedded_can::Frame as _;
    let text = std::str::from_utf8(line).ok()?;
    let text = text.strip_prefix('z').unwrap_or(text);
    let rest = text.strip_prefix('t')?;
    let id = u16::from_str_radix(rest.get(0..3)?, 16).ok()?;
    let len = usize::from(rest.get(3..4)?.parse::<u8>().ok()?);
    if len > 8 {
        return None;
    }
    let hex = rest.get(4..4 + 2 * len)?;
    let data: Vec<u8> = (0..len)
        .map(|i| u8::from_str_radix(hex.get(2 * i..2 * i + 2)?, 16).ok())
        .collect::<Option<_>>()?;
    let id = embedded_can::StandardId::new(id)?;
    let frame = can::Frame::new(id, &data)?;
    can::decode(&frame).ok()
}

impl Transport for Slcan {
    fn link(&self) -> Link {
        Link::ClassicCan
    }

    fn device(&self) -> String {
        self.line.device()
    }

    fn gate(&self) -> &Gate {
        &self.gate
    }

    async fn recv(&mut self) -> Result<Packet, TransportError> {
        self.line.recv().await
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use firmware_protocol::message::Sync;
    use firmware_protocol::{Message, NodeId};

    #[test]
    fn frames_round_trip_through_slcan_text() {
        let node = NodeId::new(3).unwrap();
        let packet =
            Packet::node(node, Message::Control(firmware_protocol::drive::DriveCommand::Enable));
        let text = format_frame(&can::encode(&packet).unwrap()).unwrap();
        assert_eq!(text, "t2C3101\r");
        assert_eq!(parse_line(text.trim_end().as_bytes()), Some(packet));
        let sync = Packet::broadcast(Message::Sync(Sync { duration_ms: 2000 }));
        let text = format_frame(&can::encode(&sync).unwrap()).unwrap();
        assert_eq!(text, "t0402D007\r");
        // A timestamped line, and what is not a frame.
        assert_eq!(parse_line(b"t0402D0071234"), Some(sync));
        assert_eq!(parse_line(b"z"), None);
        assert_eq!(parse_line(b"t04"), None);
        assert_eq!(parse_line(b"T0000004000"), None);
    }
}
