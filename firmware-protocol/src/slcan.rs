//! The slcan (Lawicel ASCII) text of a classic CAN frame, as USB-CAN adapters (CANable,
//! CANtact, USBtin), python-can's `slcan` interface and `slcand` speak it: `tIIILDD..` — `t`,
//! the standard id in 3 hex digits, the length 0..=8 in one digit, the data in hex — then,
//! when the adapter's timestamps are on, 4 hex digits of milliseconds (0..=59999), and `\r`.
//!
//! One codec for both ends of an slcan link: the host's adapter driver and the simulated
//! adapter. No allocation: a line fits a [`Line`]. Only what this protocol uses is here (no
//! extended `T`, remote `r`/`R` or FD `d`/`b` frames: its frames are standard data frames,
//! and slcan adapters are classic CAN).

use core::fmt::Write as _;

use embedded_can::{Frame as _, StandardId};

use crate::can::{CLASSIC_MAX_LEN, Frame};

/// The longest frame line: `t`, 3 id digits, 1 length digit, 16 data digits, 4 timestamp
/// digits, `\r`.
pub const MAX_FRAME_LINE: usize = 1 + 3 + 1 + 2 * CLASSIC_MAX_LEN + 4 + 1;

/// One frame line.
pub type Line = heapless::String<MAX_FRAME_LINE>;

/// The line of a classic `frame` (ending in `\r`), with `timestamp_ms` (taken modulo 60000,
/// as adapters count) if given; `None` for a CAN FD frame, which slcan cannot carry.
pub fn format(frame: &Frame, timestamp_ms: Option<u16>) -> Option<Line> {
    if frame.is_fd() {
        return None;
    }
    let mut line = Line::new();
    // At most MAX_FRAME_LINE characters go in, so no write can fail.
    write!(line, "t{:03X}{}", frame.standard_id().as_raw(), frame.dlc()).ok()?;
    for byte in frame.data() {
        write!(line, "{byte:02X}").ok()?;
    }
    if let Some(ms) = timestamp_ms {
        write!(line, "{:04X}", ms % 60_000).ok()?;
    }
    line.push('\r').ok()?;
    Some(line)
}

/// A frame line (without its `\r`): the frame and its timestamp, if the line has one;
/// `None` for anything else (another command, a wrong length, a non-hex digit, trailing
/// characters).
pub fn parse(line: &[u8]) -> Option<(Frame, Option<u16>)> {
    let text = core::str::from_utf8(line).ok()?.strip_prefix('t')?;
    let id = hex(text.get(..3)?)?;
    let len = usize::from(text.get(3..4)?.parse::<u8>().ok()?);
    if len > CLASSIC_MAX_LEN {
        return None;
    }
    let rest = text.get(4..)?;
    let (data_hex, stamp) = match rest.len().checked_sub(2 * len)? {
        0 => (rest, None),
        4 => (rest.get(..2 * len)?, Some(hex(rest.get(2 * len..)?)?)),
        _ => return None,
    };
    let mut data = [0u8; CLASSIC_MAX_LEN];
    for (i, byte) in data.iter_mut().take(len).enumerate() {
        *byte = u8::try_from(hex(data_hex.get(2 * i..2 * i + 2)?)?).ok()?;
    }
    let frame = Frame::new(StandardId::new(id)?, &data[..len])?;
    Some((frame, stamp))
}

/// Hex digits only (no sign, unlike `from_str_radix`).
fn hex(digits: &str) -> Option<u16> {
    if !digits.bytes().all(|b| b.is_ascii_hexdigit()) {
        return None;
    }
    u16::from_str_radix(digits, 16).ok()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::message::Sync;
    use crate::{Message, NodeId, Packet, can};

    #[test]
    fn frames_round_trip_through_slcan_text() {
        let node = NodeId::new(3).unwrap();
        let packet = Packet::node(node, Message::Control(crate::drive::DriveCommand::Enable));
        let frame = can::encode(&packet).unwrap();
        let line = format(&frame, None).unwrap();
        assert_eq!(line.as_str(), "t2C3101\r");
        assert_eq!(parse(line.trim_end().as_bytes()), Some((frame, None)));
        let sync = can::encode(&Packet::broadcast(Message::Sync(Sync { duration_ms: 2000 })));
        let sync = sync.unwrap();
        assert_eq!(format(&sync, None).unwrap().as_str(), "t0402D007\r");
        // A timestamp, counted modulo a minute.
        assert_eq!(format(&sync, Some(60_001)).unwrap().as_str(), "t0402D0070001\r");
        assert_eq!(parse(b"t0402D0071234"), Some((sync, Some(0x1234))));
    }

    #[test]
    fn what_is_not_a_frame_line_is_refused() {
        assert!(parse(b"t3800").is_some_and(|(f, _)| f.data().is_empty()));
        for bad in [
            "z",
            "t04",
            "T0000004000",
            "t2C31",
            "t800",
            "t8000",
            "t3809",
            "t38",
            "t2C31G1",
            "t2C3101FF",
            "t2C3101FFFFFF",
            "txyz0",
            "t-010",
            "t2C31+1",
        ] {
            assert_eq!(parse(bad.as_bytes()), None, "{bad}");
        }
        let fd = Frame::new(StandardId::new(0x100).unwrap(), &[0; 16]).unwrap();
        assert_eq!(format(&fd, None), None);
    }
}
