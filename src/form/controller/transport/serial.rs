//! The protocol's serial mapping on a serial port (1 Mbaud 8N1): every packet is a frame
//! `address, sequence, code, payload, CRC-16`, COBS-encoded and ended by `0x00`
//! (`firmware_protocol::serial`).
//!
//! Packet handling: the host numbers its requests; sending the same packet again (a retry)
//! reuses its number, as the protocol asks. Received frames that fail to decode are dropped
//! (the decoder resynchronises at the next `0x00`). Nodes on a serial line speak only when
//! polled, which the session does ([`Link::Serial`]).

use std::path::Path;

use firmware_protocol::{Link, Packet, serial};

use super::gate::{Gate, PacketSink};
use super::line::{Line, Writer};
use super::{Transport, TransportError};

/// The line speed of the serial mapping.
pub const BAUD: u32 = 1_000_000;

/// A serial port speaking the serial mapping.
#[derive(Debug)]
pub struct SerialLine {
    line: Line,
    gate: Gate,
}

/// The writing side: numbers the frames (a retry keeps its number, as the protocol asks).
struct Numbered {
    writer: Writer,
    seq: u8,
    last: Option<Packet>,
}

impl PacketSink for Numbered {
    fn write(&mut self, packet: &Packet) -> Result<(), TransportError> {
        if self.last != Some(*packet) {
            self.seq = self.seq.wrapping_add(1);
            self.last = Some(*packet);
        }
        let wire =
            serial::encode(&serial::Frame { seq: self.seq, packet: *packet }).map_err(|e| {
                TransportError::Unsupported {
                    device: self.writer.device().to_string(),
                    what: format!("{}: {e}", packet.message.code().name()),
                }
            })?;
        self.writer.write(&wire)
    }
}

impl SerialLine {
    /// Opens the port and flushes the nodes' partial frame with a lone `0x00`.
    pub fn open(path: &Path) -> Result<Self, TransportError> {
        let mut decoder = serial::Decoder::new();
        let (line, mut writer) = Line::open(path, BAUD, move |bytes, out| {
            out.extend(decoder.feed(bytes).filter_map(Result::ok).map(|frame| frame.packet));
        })?;
        writer.write(&[0])?;
        let gate = Gate::new(line.device(), Numbered { writer, seq: 0, last: None });
        Ok(Self { line, gate })
    }
}

/// A gate that writes frames to `path` beside the process holding it ([`Writer::shared`]):
/// the nodes' decoders resynchronise at the frame delimiter, so a frame of the holder's that
/// the stop interrupts is lost, the stop itself is not (it is sent several times).
pub fn shared_gate(path: &Path) -> Result<Gate, TransportError> {
    let mut writer = Writer::shared(path)?;
    // End whatever partial frame the holder may be writing.
    writer.write(&[0])?;
    Ok(Gate::new(path.display().to_string(), Numbered { writer, seq: 0, last: None }))
}

impl Transport for SerialLine {
    fn link(&self) -> Link {
        Link::Serial
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
