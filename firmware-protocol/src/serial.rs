//! The serial mapping: the same packets over a byte stream (RS-485 multi-drop, USB-serial).
//!
//! **Frame** (before COBS), all little-endian:
//!
//! | offset   | field                                                              |
//! |----------|--------------------------------------------------------------------|
//! | 0        | address: 0 = broadcast, 1..=63 = node (receiver or sender, as on CAN) |
//! | 1        | sequence number                                                    |
//! | 2        | function [`Code`]                                                  |
//! | 3..n-2   | payload, the message's [`payload`] layout (≤ [`MAX_PAYLOAD`]) |
//! | n-2..n   | CRC over bytes 0..n-2, little-endian (see below)                   |
//!
//! The CRC is CRC-16/IBM-SDLC, the HDLC / X.25 / PPP frame check sequence: polynomial
//! 0x1021, reflected in and out, initial value 0xFFFF, final XOR 0xFFFF; check value 0x906E
//! for the ASCII bytes `123456789`. Being reflected, it belongs after the data low byte
//! first, which keeps its guarantees: every error burst of up to 16 bits and every odd
//! number of bit errors is detected.
//!
//! The frame is COBS-encoded (no 0x00 inside) and followed by one `0x00` delimiter, so it is
//! at most [`MAX_FRAME_LEN`] bytes on the wire.
//!
//! **Resynchronisation**: every `0x00` ends a frame. A receiver ([`Decoder`]) decodes what
//! came since the previous `0x00`, reports bad frames ([`Error`]) and carries on; after more
//! than [`MAX_ENCODED_LEN`] bytes without a delimiter it reports [`Error::Overflow`] once and
//! drops bytes up to the next `0x00`. Empty frames (`0x00 0x00`) are ignored, so a sender
//! may send a lone `0x00` to flush a receiver's partial frame (do so after opening a port).
//!
//! **Sequence numbers**: the host numbers its requests (wrapping `u8`); a node copies the
//! sequence number of the request into every frame it sends in answer. The host retries an
//! unanswered request with the same number; requests are idempotent, so a node simply
//! executes it again.
//!
//! **Who speaks when**: the line is shared and half-duplex, so a node sends only in answer
//! to a frame addressed to it (never to a broadcast), starting within
//! [`SERIAL_REPLY_WITHIN_MS`](crate::timing::SERIAL_REPLY_WITHIN_MS). An addressed
//! `HostHeartbeat` is the poll: the node answers `Heartbeat`, `AllFeedback`, then
//! `AllForce` if the poll announces protocol 1.1 or later, then any pending `Emergency`
//! events, oldest first.

use crate::Error;
use crate::message::{Address, Code, Packet};
use crate::payload;

/// Longest payload a serial frame carries (that of a CAN FD frame).
pub const MAX_PAYLOAD: usize = 64;
/// Bytes of the header (address, sequence number, code).
const HEADER_LEN: usize = 3;
/// Bytes of the CRC.
const CRC_LEN: usize = 2;
/// Longest frame before COBS.
pub const MAX_RAW_LEN: usize = HEADER_LEN + MAX_PAYLOAD + CRC_LEN;
/// Longest COBS-encoded frame, without its delimiter.
pub const MAX_ENCODED_LEN: usize = cobs::max_encoding_length(MAX_RAW_LEN);
/// Longest frame on the wire, delimiter included.
pub const MAX_FRAME_LEN: usize = MAX_ENCODED_LEN + 1;

// Every message of this version fits a serial frame.
const _: () = assert!(payload::MAX_LEN <= MAX_PAYLOAD);

/// CRC-16/IBM-SDLC (also known as CRC-16/X-25).
const CRC: crc::Crc<u16> = crc::Crc::<u16>::new(&crc::CRC_16_IBM_SDLC);

/// Bytes on the wire for a frame carrying `payload_len` payload bytes (at most
/// [`MAX_PAYLOAD`]), delimiter included.
pub const fn frame_len(payload_len: usize) -> usize {
    cobs::max_encoding_length(HEADER_LEN + payload_len + CRC_LEN) + 1
}

/// A packet with its sequence number: what one serial frame carries.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Frame {
    /// The request's sequence number (answers copy it).
    pub seq: u8,
    /// The packet.
    pub packet: Packet,
}

/// Encodes a frame for the wire, delimiter included; fails only for an address the message
/// does not allow.
pub fn encode(frame: &Frame) -> Result<heapless::Vec<u8, MAX_FRAME_LEN>, Error> {
    frame.packet.check_address()?;
    let payload = payload::encode(&frame.packet.message);
    let payload = payload.as_slice();
    let mut raw = [0u8; MAX_RAW_LEN];
    raw[0] = frame.packet.address.to_u8();
    raw[1] = frame.seq;
    raw[2] = frame.packet.message.code() as u8;
    let crc_at = HEADER_LEN + payload.len();
    raw[HEADER_LEN..crc_at].copy_from_slice(payload);
    let crc = CRC.checksum(&raw[..crc_at]).to_le_bytes();
    raw[crc_at..crc_at + CRC_LEN].copy_from_slice(&crc);

    // The buffer holds the longest encoding plus the delimiter, which is already 0.
    let mut wire = [0u8; MAX_FRAME_LEN];
    let len = cobs::encode(&raw[..crc_at + CRC_LEN], &mut wire[..MAX_ENCODED_LEN]);
    let mut out = heapless::Vec::from_array(wire);
    out.truncate(len + 1);
    Ok(out)
}

/// Decodes one COBS-encoded frame, given without its delimiter.
pub fn decode(encoded: &[u8]) -> Result<Frame, Error> {
    if encoded.len() > MAX_ENCODED_LEN {
        return Err(Error::Overflow);
    }
    if encoded.contains(&0) {
        return Err(Error::Framing);
    }
    let mut raw = [0u8; MAX_RAW_LEN];
    let len = cobs::decode(encoded, &mut raw).map_err(|_| Error::Framing)?.frame_size();
    let raw = raw.get(..len).ok_or(Error::Framing)?;
    if raw.len() < HEADER_LEN + CRC_LEN {
        return Err(Error::ShortFrame);
    }
    let (body, crc) = raw.split_at(raw.len() - CRC_LEN);
    if CRC.checksum(body).to_le_bytes() != crc {
        return Err(Error::Crc);
    }
    let &[address, seq, code, ref payload @ ..] = body else { return Err(Error::ShortFrame) };
    let address = Address::from_u8(address).ok_or(Error::InvalidAddress)?;
    let code = Code::from_u8(code).ok_or(Error::UnknownCode(code))?;
    let packet = Packet { address, message: payload::decode(code, payload)? };
    packet.check_address()?;
    Ok(Frame { seq, packet })
}

/// A streaming decoder: feed it bytes as they arrive, get frames (or errors) out. It holds
/// one bounded buffer and never allocates.
#[derive(Clone, Debug, Default)]
pub struct Decoder {
    buf: heapless::Vec<u8, MAX_ENCODED_LEN>,
    /// Dropping bytes up to the next delimiter after an overflow.
    skipping: bool,
}

impl Decoder {
    /// A decoder waiting for the first frame.
    pub const fn new() -> Self {
        Self { buf: heapless::Vec::new(), skipping: false }
    }

    /// Takes one byte; returns a result when it completes a frame (or overflows the buffer).
    pub fn push(&mut self, byte: u8) -> Option<Result<Frame, Error>> {
        if byte == 0 {
            let result = (!self.skipping && !self.buf.is_empty()).then(|| decode(&self.buf));
            self.buf.clear();
            self.skipping = false;
            return result;
        }
        if self.skipping {
            return None;
        }
        if self.buf.push(byte).is_err() {
            self.buf.clear();
            self.skipping = true;
            return Some(Err(Error::Overflow));
        }
        None
    }

    /// Takes a chunk of bytes; yields a result for every frame they complete.
    pub fn feed<'a>(
        &'a mut self,
        bytes: &'a [u8],
    ) -> impl Iterator<Item = Result<Frame, Error>> + 'a {
        bytes.iter().filter_map(|&byte| self.push(byte))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::drive::DriveCommand;
    use crate::message::{Message, NodeId, Sync};

    fn sync_frame() -> Frame {
        Frame { seq: 7, packet: Packet::broadcast(Message::Sync(Sync { duration_ms: 2000 })) }
    }

    #[test]
    fn crc_is_the_catalogued_ibm_sdlc() {
        assert_eq!(CRC.checksum(b"123456789"), 0x906E);
    }

    #[test]
    fn frames_have_the_bytes_of_the_readme_examples() {
        // Sync: raw 00 07 01 D0 07 + CRC 0E E9; COBS replaces the leading 00; delimiter.
        let wire = encode(&sync_frame()).unwrap();
        assert_eq!(wire[..], [0x01, 0x07, 0x07, 0x01, 0xD0, 0x07, 0x0E, 0xE9, 0x00]);
        assert_eq!(wire.len(), frame_len(2));
        assert_eq!(decode(&wire[..wire.len() - 1]), Ok(sync_frame()));
        // Control Enable to node 3, sequence 0x2A: raw 03 2A 0B 01 + CRC 73 5C.
        let node = NodeId::new(3).unwrap();
        let enable =
            Frame { seq: 0x2A, packet: Packet::node(node, Message::Control(DriveCommand::Enable)) };
        let wire = encode(&enable).unwrap();
        assert_eq!(wire[..], [0x07, 0x03, 0x2A, 0x0B, 0x01, 0x73, 0x5C, 0x00]);
    }

    #[test]
    fn bounds_are_consistent() {
        assert_eq!(MAX_FRAME_LEN, frame_len(MAX_PAYLOAD));
        assert_eq!(MAX_FRAME_LEN, 71);
    }

    #[test]
    fn decoder_skips_an_overlong_run_and_recovers_at_the_next_delimiter() {
        let mut decoder = Decoder::new();
        let garbage = [0x55u8; 3 * MAX_FRAME_LEN];
        let errors: Vec<_> = decoder.feed(&garbage).collect();
        assert_eq!(errors, [Err(Error::Overflow)]);
        let wire = encode(&sync_frame()).unwrap();
        // The first delimiter only ends the skipped run; the frame after it decodes.
        let mut stream = vec![0];
        stream.extend_from_slice(&wire);
        assert_eq!(decoder.feed(&stream).collect::<Vec<_>>(), [Ok(sync_frame())]);
    }

    #[test]
    fn empty_frames_are_ignored_and_short_ones_reported() {
        let mut decoder = Decoder::new();
        assert!(decoder.feed(&[0, 0, 0]).next().is_none());
        assert_eq!(decoder.feed(&[3, 1, 2, 0]).collect::<Vec<_>>(), [Err(Error::ShortFrame)]);
    }

    #[test]
    fn node_answers_carry_the_sender_address() {
        let node = NodeId::new(9).unwrap();
        let frame = Frame { seq: 1, packet: Packet::node(node, Message::IdentifyRequest) };
        let wire = encode(&frame).unwrap();
        assert_eq!(wire[1], 9);
        assert_eq!(decode(&wire[..wire.len() - 1]), Ok(frame));
    }
}
