//! The links to the form behind one async interface, [`Transport`]: send a packet, receive
//! the next packet.
//!
//! | link | type | framing | nodes speak |
//! |---|---|---|---|
//! | in-process simulated CAN bus | [`sim::SimBus`] | `can::encode` / `can::decode` | cyclically (CAN) |
//! | serial port (USB-serial, RS-485) | [`serial::SerialLine`] | the serial mapping (COBS, CRC-16, sequence numbers) | only when polled |
//! | slcan (Lawicel USB-CAN adapter) on a serial port | [`slcan::Slcan`] | `tIIILDD..\r` text, classic CAN only | cyclically (CAN) |
//! | SocketCAN interface | [`socketcan::SocketCan`] | kernel CAN frames, classic CAN | cyclically (CAN) |
//!
//! Every link sends through its [`Gate`]: the e-stop path (see [`gate`]). The simulated bus
//! and SocketCAN are there with the cargo features `simulator` and `socketcan` (default); the
//! serial links, and with them the e-stop over serial and slcan, are in every build.
//!
//! Packet handling: a received frame that does not decode (bad CRC, unknown code, invalid
//! field, an extended or remote CAN frame) is dropped and counted, never an error; only the
//! link itself failing is. Packets the link cannot carry (a 16-byte `AllTargets` on classic
//! CAN or slcan) are refused with [`TransportError::Unsupported`] before anything is sent;
//! the session asks [`Transport::link`] and sends `Targets` halves on classic links.

pub mod gate;
pub mod serial;
#[cfg(feature = "simulator")]
pub mod sim;
pub mod slcan;
#[cfg(feature = "socketcan")]
pub mod socketcan;

mod line;

use std::future::Future;
use std::path::PathBuf;

use firmware_protocol::{Link, Packet};

pub use gate::{EMERGENCY_STOP_REPEATS, Gate, PacketSink, StopCause};

/// Why a link failed.
#[derive(Debug, thiserror::Error)]
pub enum TransportError {
    /// The device or socket failed.
    #[error("{device}: {source}")]
    Io {
        /// The device, port or interface.
        device: String,
        /// What the operating system said.
        source: std::io::Error,
    },
    /// The link closed (the simulated bus ended, the port's reader stopped).
    #[error("{0}: the link closed")]
    Closed(String),
    /// The link cannot carry this packet.
    #[error("{device}: cannot send {what} on this link")]
    Unsupported {
        /// The device.
        device: String,
        /// The packet.
        what: String,
    },
    /// This dressform was built without the cargo feature the link needs.
    #[error("{device}: this dressform was built without {feature}")]
    NotBuilt {
        /// The device.
        device: String,
        /// The missing feature, as the message names it.
        feature: &'static str,
    },
    /// The link was e-stopped: only emergency stops go out any more.
    #[error("{device}: stopped by {cause}")]
    Stopped {
        /// The device.
        device: String,
        /// Who stopped it.
        cause: StopCause,
    },
}

/// A link to the form's nodes.
pub trait Transport: Send {
    /// The link's kind: classic CAN, CAN FD or serial (which decides the target frames and
    /// whether nodes must be polled).
    fn link(&self) -> Link;

    /// A name for messages (`/dev/ttyUSB0`, `can0`, `simulated bus`).
    fn device(&self) -> String;

    /// The link's sending half, shared with the e-stop.
    fn gate(&self) -> &Gate;

    /// Sends one packet through the gate (returns once it is handed to the link).
    fn send(&mut self, packet: Packet) -> impl Future<Output = Result<(), TransportError>> + Send {
        let sent = self.gate().send(&packet);
        async move { sent }
    }

    /// The next packet received. Cancel-safe: dropping the future loses nothing.
    fn recv(&mut self) -> impl Future<Output = Result<Packet, TransportError>> + Send;
}

/// Where the form is, as the command line names it.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum LinkSpec {
    /// The in-process simulated form (see [`crate::form::controller::simulated`]).
    Sim,
    /// A serial port speaking the serial mapping.
    Serial(PathBuf),
    /// An slcan adapter on a serial port.
    Slcan(PathBuf),
    /// A SocketCAN interface.
    Can(String),
}

/// Any of the links. Hardware links open from a [`LinkSpec`] here; the simulated bus needs a
/// simulated form on it ([`crate::form::controller::open::OpenLink`] opens either).
#[derive(Debug)]
pub enum Connection {
    /// A serial port.
    Serial(serial::SerialLine),
    /// An slcan adapter.
    Slcan(slcan::Slcan),
    /// A SocketCAN interface.
    #[cfg(feature = "socketcan")]
    Can(socketcan::SocketCan),
    /// The simulated bus.
    #[cfg(feature = "simulator")]
    Sim(sim::SimBus),
}

impl Connection {
    /// Opens a hardware link; `LinkSpec::Sim` is refused (it needs a simulated form).
    pub fn open(spec: &LinkSpec) -> Result<Self, TransportError> {
        match spec {
            LinkSpec::Serial(path) => Ok(Self::Serial(serial::SerialLine::open(path)?)),
            LinkSpec::Slcan(path) => Ok(Self::Slcan(slcan::Slcan::open(path)?)),
            #[cfg(feature = "socketcan")]
            LinkSpec::Can(iface) => Ok(Self::Can(socketcan::SocketCan::open(iface)?)),
            #[cfg(not(feature = "socketcan"))]
            LinkSpec::Can(iface) => Err(TransportError::NotBuilt {
                device: iface.clone(),
                feature: "SocketCAN (cargo feature `socketcan`)",
            }),
            LinkSpec::Sim => Err(TransportError::Unsupported {
                device: "simulated bus".into(),
                what: "a connection without a simulated form".into(),
            }),
        }
    }
}

/// A gate on `spec`'s link that needs no lock on it: for an emergency stop when the link is
/// held by a process that cannot be reached (see [`super::control`]). Serial devices are
/// written beside their holder ([`serial::shared_gate`], [`slcan::shared_gate`]); a SocketCAN
/// interface takes any number of sockets, so it is opened as usual.
pub fn shared_stop_gate(spec: &LinkSpec) -> Result<Gate, TransportError> {
    match spec {
        LinkSpec::Serial(path) => serial::shared_gate(path),
        LinkSpec::Slcan(path) => slcan::shared_gate(path),
        LinkSpec::Can(_) | LinkSpec::Sim => Connection::open(spec).map(|c| c.gate().clone()),
    }
}

impl Transport for Connection {
    fn link(&self) -> Link {
        match self {
            Self::Serial(t) => t.link(),
            Self::Slcan(t) => t.link(),
            #[cfg(feature = "socketcan")]
            Self::Can(t) => t.link(),
            #[cfg(feature = "simulator")]
            Self::Sim(t) => t.link(),
        }
    }

    fn device(&self) -> String {
        match self {
            Self::Serial(t) => t.device(),
            Self::Slcan(t) => t.device(),
            #[cfg(feature = "socketcan")]
            Self::Can(t) => t.device(),
            #[cfg(feature = "simulator")]
            Self::Sim(t) => t.device(),
        }
    }

    fn gate(&self) -> &Gate {
        match self {
            Self::Serial(t) => t.gate(),
            Self::Slcan(t) => t.gate(),
            #[cfg(feature = "socketcan")]
            Self::Can(t) => t.gate(),
            #[cfg(feature = "simulator")]
            Self::Sim(t) => t.gate(),
        }
    }

    async fn recv(&mut self) -> Result<Packet, TransportError> {
        match self {
            Self::Serial(t) => t.recv().await,
            Self::Slcan(t) => t.recv().await,
            #[cfg(feature = "socketcan")]
            Self::Can(t) => t.recv().await,
            #[cfg(feature = "simulator")]
            Self::Sim(t) => t.recv().await,
        }
    }
}
