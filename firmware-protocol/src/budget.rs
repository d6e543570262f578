//! How long frames occupy the bus, so the simulated bus and the README share one formula.
//!
//! * **Classic CAN 2.0A**, worst case with bit stuffing (Davis, Burns, Bril, Lukkien 2007,
//!   "CAN schedulability analysis: refuted, revisited and revised"), for `n` data bytes:
//!   `34 + 8n` stuffable bits (SOF to CRC), at most one stuff bit per 4 of them after the
//!   first, plus 13 fixed bits (CRC delimiter, ACK, EOF, 3-bit intermission):
//!   `bits = 8n + 47 + ⌊(34 + 8n − 1) / 4⌋`, e.g. 135 bits for 8 bytes, 55 for none.
//! * **CAN FD** base format (ISO 11898-1:2015) with bit-rate switching, the same worst-case
//!   stuffing: at the nominal rate SOF to BRS (17 bits, ≤ 4 stuff bits), the CRC delimiter,
//!   ACK, ACK delimiter, EOF and intermission (13 bits): 34 bits; at the data rate ESI, DLC,
//!   the data (padded to a CAN FD length), their dynamic stuff bits, the stuff count (4),
//!   the CRC (17 bits up to 16 data bytes, else 21) and its fixed stuff bits (one per 4 bits
//!   of stuff count and CRC). Messages of up to 8 bytes go as classic frames (see
//!   [`can`](crate::can)).
//! * **Serial**: [`serial::frame_len`] bytes of 10 bits (8N1),
//!   line turnaround not counted.

use crate::Link;
use crate::can::CLASSIC_MAX_LEN;
use crate::serial;

/// Bits a classic CAN 2.0A data frame with `len` (≤ 8) data bytes takes on the bus, worst
/// case, interframe space included.
pub const fn classic_frame_bits(len: usize) -> u32 {
    let stuffable = 34 + 8 * len as u32;
    stuffable + 13 + (stuffable - 1) / 4
}

/// The data length a CAN FD frame needs to carry `len` bytes (the next of 0..=8, 12, 16,
/// 20, 24, 32, 48, 64).
pub const fn fd_padded_len(len: usize) -> usize {
    match len {
        0..=8 => len,
        9..=24 => len.div_ceil(4) * 4,
        25..=32 => 32,
        33..=48 => 48,
        _ => 64,
    }
}

/// Bits of a CAN FD frame at each bit rate.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct FdFrameBits {
    /// Bits at the nominal (arbitration) rate.
    pub nominal: u32,
    /// Bits at the data rate.
    pub data: u32,
}

/// Bits a CAN FD data frame (11-bit id, bit-rate switching) with `len` data bytes takes on
/// the bus, worst case, interframe space included.
pub const fn fd_frame_bits(len: usize) -> FdFrameBits {
    const ARBITRATION: u32 = 17; // SOF, 11-bit id, RRS, IDE, FDF, res, BRS
    const ARBITRATION_STUFF: u32 = (ARBITRATION - 1) / 4;
    let data_bits = 8 * fd_padded_len(len) as u32;
    let crc: u32 = if data_bits <= 16 * 8 { 17 } else { 21 };
    let stuffed = ARBITRATION + 5 + data_bits; // ... ESI, DLC, data
    let data_stuff = (stuffed - 1) / 4 - ARBITRATION_STUFF;
    let fixed_stuff = (4 + crc).div_ceil(4);
    FdFrameBits {
        nominal: ARBITRATION + ARBITRATION_STUFF + 1 + 12,
        data: 5 + data_bits + data_stuff + 4 + crc + fixed_stuff,
    }
}

/// A bus or line and its bit rates.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Bus {
    /// Classic CAN at `bitrate` bit/s.
    ClassicCan {
        /// Bit rate, bit/s.
        bitrate: u32,
    },
    /// CAN FD: arbitration at `nominal`, data phase at `data` bit/s.
    CanFd {
        /// Nominal (arbitration) bit rate, bit/s.
        nominal: u32,
        /// Data-phase bit rate, bit/s.
        data: u32,
    },
    /// A serial line at `baud` (8N1).
    Serial {
        /// Baud rate.
        baud: u32,
    },
}

impl Bus {
    /// Which messages this bus carries.
    pub const fn link(self) -> Link {
        match self {
            Self::ClassicCan { .. } => Link::ClassicCan,
            Self::CanFd { .. } => Link::CanFd,
            Self::Serial { .. } => Link::Serial,
        }
    }

    /// Nanoseconds a frame with `payload_len` payload bytes occupies the bus, worst case.
    pub const fn frame_time_ns(self, payload_len: usize) -> u64 {
        const NS: u64 = 1_000_000_000;
        match self {
            Self::ClassicCan { bitrate } => {
                classic_frame_bits(payload_len) as u64 * NS / bitrate as u64
            }
            Self::CanFd { nominal, .. } if payload_len <= CLASSIC_MAX_LEN => {
                classic_frame_bits(payload_len) as u64 * NS / nominal as u64
            }
            Self::CanFd { nominal, data } => {
                let bits = fd_frame_bits(payload_len);
                bits.nominal as u64 * NS / nominal as u64 + bits.data as u64 * NS / data as u64
            }
            Self::Serial { baud } => serial::frame_len(payload_len) as u64 * 10 * NS / baud as u64,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn classic_frames_match_the_published_worst_case() {
        // Davis et al. (2007), Table: 135 bits for 8 data bytes, 55 bits for none.
        assert_eq!(classic_frame_bits(8), 135);
        assert_eq!(classic_frame_bits(0), 55);
        assert_eq!(classic_frame_bits(2), 75);
    }

    #[test]
    fn fd_frames_add_up_field_by_field() {
        // 16 bytes: data phase = ESI+DLC 5, data 128, stuff ⌊149/4⌋−4 = 33, stuff count 4,
        // CRC-17, 6 fixed stuff bits.
        assert_eq!(fd_frame_bits(16), FdFrameBits { nominal: 34, data: 5 + 128 + 33 + 4 + 17 + 6 });
        // 64 bytes switch to CRC-21 with 7 fixed stuff bits.
        assert_eq!(fd_frame_bits(64).data, 5 + 512 + (533 / 4 - 4) + 4 + 21 + 7);
        assert_eq!(fd_padded_len(9), 12);
        assert_eq!(fd_padded_len(33), 48);
    }

    #[test]
    fn frame_times_follow_the_bit_rates() {
        let classic = Bus::ClassicCan { bitrate: 1_000_000 };
        assert_eq!(classic.frame_time_ns(8), 135_000);
        let fd = Bus::CanFd { nominal: 1_000_000, data: 5_000_000 };
        assert_eq!(fd.frame_time_ns(8), 135_000);
        assert_eq!(fd.frame_time_ns(16), 34_000 + 193 * 200);
        let serial = Bus::Serial { baud: 1_000_000 };
        assert_eq!(serial.frame_time_ns(16), 23 * 10_000);
    }
}
