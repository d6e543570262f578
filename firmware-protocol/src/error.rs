//! Why a frame could not be encoded or decoded.

use core::fmt;

/// Why a frame could not be encoded or decoded. Decoders return it for any bad input;
/// they never panic.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Error {
    /// The function code is not one of this protocol version.
    UnknownCode(u8),
    /// The payload is shorter than the message's layout.
    Truncated,
    /// A field holds a value outside its range (named).
    InvalidField(&'static str),
    /// The address is not allowed for this message (a broadcast set-point, an addressed
    /// e-stop, a node id above 63, a node message from address 0).
    InvalidAddress,
    /// A CAN frame this protocol does not use: extended identifier or remote frame.
    UnsupportedFrame,
    /// Serial: not a valid COBS frame, or a 0x00 inside it.
    Framing,
    /// Serial: the decoded frame is shorter than header and CRC.
    ShortFrame,
    /// Serial: the CRC does not match.
    Crc,
    /// Serial: more than [`MAX_ENCODED_LEN`](crate::serial::MAX_ENCODED_LEN) bytes without a
    /// delimiter; bytes are dropped until the next 0x00.
    Overflow,
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::UnknownCode(code) => write!(f, "unknown function code {code}"),
            Self::Truncated => f.write_str("payload shorter than the message layout"),
            Self::InvalidField(field) => write!(f, "field `{field}` out of range"),
            Self::InvalidAddress => f.write_str("address not allowed for this message"),
            Self::UnsupportedFrame => f.write_str("extended-id or remote CAN frame"),
            Self::Framing => f.write_str("invalid COBS framing"),
            Self::ShortFrame => f.write_str("serial frame shorter than header and CRC"),
            Self::Crc => f.write_str("CRC mismatch"),
            Self::Overflow => f.write_str("serial frame too long; resynchronising"),
        }
    }
}

impl core::error::Error for Error {}

#[cfg(feature = "std")]
impl From<Error> for std::io::Error {
    /// For host codecs whose error type is `io::Error` (e.g. `tokio_util::codec`).
    fn from(error: Error) -> Self {
        std::io::Error::new(std::io::ErrorKind::InvalidData, error)
    }
}
