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

use firmware_protocol::{Link, Packet, can, slcan};

use super::gate::{Gate, PacketSink};
use super::line::{Line, Writer};
use super::{Transport, TransportError};

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
        let text =
            slcan::format(&frame, None).ok_or_else(|| unsupported("not a classic CAN frame"))?;
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

/// A gate that writes frame lines to the adapter at `path` beside the process holding it
/// ([`Writer::shared`]; the adapter's channel is open, as its holder left it): a line of the
/// holder's that the stop interrupts is lost at its `\r`, the stop itself is not (it is sent
/// several times).
pub fn shared_gate(path: &Path) -> Result<Gate, TransportError> {
    let mut writer = Writer::shared(path)?;
    // End whatever partial line the holder may be writing.
    writer.write(b"\r")?;
    Ok(Gate::new(path.display().to_string(), Lines(writer)))
}

/// The packet of a received line (`firmware_protocol::slcan`'s frame line, the timestamp
/// ignored; a `z` acknowledgement may run into it), if it is a valid protocol frame.
pub fn parse_line(line: &[u8]) -> Option<Packet> {
    let line = line.strip_prefix(b"z").unwrap_or(line);
    let (frame, _timestamp) = slcan::parse(line)?;
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
    fn received_lines_become_packets() {
        let node = NodeId::new(3).unwrap();
        let packet =
            Packet::node(node, Message::Control(firmware_protocol::drive::DriveCommand::Enable));
        let text = slcan::format(&can::encode(&packet).unwrap(), None).unwrap();
        assert_eq!(parse_line(text.trim_end().as_bytes()), Some(packet));
        // A timestamped line, one an acknowledgement ran into, and what is not a frame.
        let sync = Packet::broadcast(Message::Sync(Sync { duration_ms: 2000 }));
        assert_eq!(parse_line(b"t0402D0071234"), Some(sync));
        assert_eq!(parse_line(b"zt0402D007"), Some(sync));
        assert_eq!(parse_line(b"z"), None);
        assert_eq!(parse_line(b"t04"), None);
        assert_eq!(parse_line(b"T0000004000"), None);
    }
}
