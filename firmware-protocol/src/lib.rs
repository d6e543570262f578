//! The wire contract between the dressform host and the controller boards ("nodes") of the
//! robotic dress form. `no_std`, no allocation; the `std` feature adds host conveniences.
//!
//! The form is up to 63 nodes on one bus, each driving up to 8 linear actuators. Host and
//! firmware exchange [`Packet`]s — a [`Message`] and an [`Address`] — over one of two
//! mappings:
//!
//! * [`can`]: classic CAN 2.0A (11-bit ids ordered by priority, ≤ 8-byte little-endian
//!   payloads) with CAN FD for the three 16-byte messages; frames implement
//!   [`embedded_can::Frame`]. [`dbc`] describes it for CAN tools; [`slcan`] is the text
//!   of a classic frame on USB-CAN adapters.
//! * [`serial`]: the same packets over a byte stream, with address, sequence number, CRC and
//!   COBS framing, and a streaming [`serial::Decoder`].
//!
//! The rest names domain concepts: [`message`] (what is said, by whom), [`payload`] (the
//! byte layouts), [`actuator`] (actuators, positions and forces), [`drive`] (the drive state
//! machine, faults, answers), [`param`] (parameters), [`timing`] (heartbeats, watchdog),
//! [`version`] (compatibility rules), [`update`] (a synchronised full-form move) and
//! [`budget`] (bus time of frames). `firmware-protocol/README.md` is the specification.
//!
//! ```
//! use firmware_protocol::{can, serial, Message, NodeId, Packet, Position};
//! use firmware_protocol::message::{Half, Positions4};
//!
//! let targets = [Position::new(1250), None, Position::new(3000), None];
//! let packet = Packet::node(
//!     NodeId::new(3).unwrap(),
//!     Message::Targets(Positions4 { half: Half::Lower, positions: targets }),
//! );
//! let frame = can::encode(&packet)?;
//! assert_eq!(can::decode(&frame)?, packet);
//!
//! let wire = serial::encode(&serial::Frame { seq: 1, packet })?;
//! let mut decoder = serial::Decoder::new();
//! assert_eq!(decoder.feed(&wire).next(), Some(Ok(serial::Frame { seq: 1, packet })));
//! # Ok::<(), firmware_protocol::Error>(())
//! ```
#![cfg_attr(not(any(feature = "std", test)), no_std)]
#![forbid(unsafe_code)]
#![warn(missing_docs)]

pub mod actuator;
pub mod budget;
pub mod can;
pub mod dbc;
pub mod drive;
mod error;
pub mod message;
pub mod param;
pub mod payload;
pub mod serial;
pub mod slcan;
pub mod timing;
pub mod update;
pub mod version;

pub use actuator::{
    Accel, Actuator, ActuatorSet, Force, HUNDREDTHS_PER_MM, HUNDREDTHS_PER_N, Position, Speed,
    TENTHS_PER_MM_S2,
};
pub use error::Error;
pub use message::{Address, Code, Message, NodeId, Packet};
pub use version::{PROTOCOL_VERSION, ProtocolVersion};

/// The kind of link between host and nodes, which decides the set-point messages used.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Link {
    /// Classic CAN: payloads of at most 8 bytes (`Targets` / `Feedback` halves).
    ClassicCan,
    /// CAN FD: 16-byte `AllTargets` / `AllFeedback` / `AllForce` too.
    CanFd,
    /// A serial line: any message, nodes speak only when polled.
    Serial,
}
