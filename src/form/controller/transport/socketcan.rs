//! A SocketCAN interface (`can0`, `vcan0`, `slcan0` after `slcand`) through the `socketcan`
//! crate's tokio socket: classic CAN 2.0A frames, 1 Mbit/s as configured with `ip link`.
//!
//! Packet handling: `can::encode` gives an `embedded_can` frame, converted to the kernel's
//! frame by [`to_socketcan`]; received frames decode straight from `socketcan::CanFrame`
//! (an `embedded_can::Frame`); extended, remote and error frames are dropped. CAN FD
//! interfaces are not supported yet: the link is classic (`Targets` halves).
//!
//! Frames go out through a blocking socket of their own (with a write timeout), which the
//! link's [`Gate`] owns, so an e-stop never waits for the runtime; frames come in through the
//! tokio socket.

use std::time::Duration;

use embedded_can::Frame as _;
use firmware_protocol::{Link, Packet, can};
use socketcan::{CanFrame, Socket as _, tokio::CanSocket};

use super::gate::{Gate, PacketSink};
use super::{Transport, TransportError};

/// The longest a frame write waits for room in the interface's queue.
const WRITE_TIMEOUT: Duration = Duration::from_millis(10);

/// An open SocketCAN interface.
pub struct SocketCan {
    interface: String,
    socket: CanSocket,
    gate: Gate,
}

/// The sending socket.
struct Writer {
    interface: String,
    socket: socketcan::CanSocket,
}

impl PacketSink for Writer {
    fn write(&mut self, packet: &Packet) -> Result<(), TransportError> {
        let frame = to_socketcan(packet).ok_or_else(|| TransportError::Unsupported {
            device: self.interface.clone(),
            what: format!("{} (not a classic CAN frame)", packet.message.code().name()),
        })?;
        self.socket
            .write_frame(&frame)
            .map_err(|source| TransportError::Io { device: self.interface.clone(), source })
    }
}

impl std::fmt::Debug for SocketCan {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("SocketCan").field("interface", &self.interface).finish_non_exhaustive()
    }
}

impl SocketCan {
    /// Opens `interface`. Fails where the kernel has no SocketCAN (`socket(AF_CAN)` fails).
    pub fn open(interface: &str) -> Result<Self, TransportError> {
        let io = |source| TransportError::Io { device: interface.to_string(), source };
        let socket = CanSocket::open(interface).map_err(io)?;
        let writer = socketcan::CanSocket::open(interface).map_err(io)?;
        writer.set_write_timeout(WRITE_TIMEOUT).map_err(io)?;
        let gate =
            Gate::new(interface, Writer { interface: interface.to_string(), socket: writer });
        Ok(Self { interface: interface.to_string(), socket, gate })
    }
}

/// The kernel frame of a packet, if it is a classic CAN frame.
pub fn to_socketcan(packet: &Packet) -> Option<CanFrame> {
    let frame = can::encode(packet).ok()?;
    if frame.is_fd() {
        return None;
    }
    CanFrame::new(frame.id(), frame.data())
}

/// The packet of a kernel frame, if it is a valid protocol frame.
pub fn from_socketcan(frame: &CanFrame) -> Option<Packet> {
    can::decode(frame).ok()
}

impl Transport for SocketCan {
    fn link(&self) -> Link {
        Link::ClassicCan
    }

    fn device(&self) -> String {
        self.interface.clone()
    }

    fn gate(&self) -> &Gate {
        &self.gate
    }

    async fn recv(&mut self) -> Result<Packet, TransportError> {
        loop {
            let frame = self
                .socket
                .read_frame()
                .await
                .map_err(|source| TransportError::Io { device: self.device(), source })?;
            if let Some(packet) = from_socketcan(&frame) {
                return Ok(packet);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use firmware_protocol::message::{Positions8, Sync};
    use firmware_protocol::{Message, NodeId, Position};

    #[test]
    fn packets_convert_to_kernel_frames_and_back() {
        let node = NodeId::new(3).unwrap();
        let mut all = Positions8::default();
        all.positions[1] = Position::new(2350);
        let targets =
            Packet::node(node, Message::Targets(all.half(firmware_protocol::message::Half::Lower)));
        for packet in [
            targets,
            Packet::broadcast(Message::Sync(Sync { duration_ms: 2000 })),
            Packet::broadcast(Message::EmergencyStop),
        ] {
            let frame = to_socketcan(&packet).unwrap();
            assert_eq!(frame.id(), can::encode(&packet).unwrap().id());
            assert_eq!(from_socketcan(&frame), Some(packet));
        }
        // FD-only packets are not classic frames.
        assert!(to_socketcan(&Packet::node(node, Message::AllTargets(all))).is_none());
        // Extended frames are not the protocol's.
        let extended = CanFrame::new(embedded_can::ExtendedId::new(0x283).unwrap(), &[1]).unwrap();
        assert_eq!(from_socketcan(&extended), None);
    }
}
