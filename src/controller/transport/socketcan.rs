//! A SocketCAN interface (`can0`, `vcan0`, `slcan0` after `slcand`) through the `socketcan`
//! crate's tokio socket: classic CAN 2.0A frames, 1 Mbit/s as configured with `ip link`.
//!
//! Packet handling: `can::encode` gives an `embedded_can` frame, converted to the kernel's
//! frame by [`to_socketcan`]; received frames decode straight from `socketcan::CanFrame`
//! (an `embedded_can::Frame`); extended, remote and error frames are dropped. CAN FD
//! interfaces are not supported yet: the link is classic (`Targets` halves).

use embedded_can::Frame as _;
use firmware_protocol::{Link, Packet, can};
use socketcan::{CanFrame, tokio::CanSocket};

use super::{Transport, TransportError};

/// An open SocketCAN interface.
pub struct SocketCan {
    interface: String,
    socket: CanSocket,
}

impl std::fmt::Debug for SocketCan {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("SocketCan").field("interface", &self.interface).finish_non_exhaustive()
    }
}

impl SocketCan {
    /// Opens `interface`. Fails where the kernel has no SocketCAN (`socket(AF_CAN)` fails).
    pub fn open(interface: &str) -> Result<Self, TransportError> {
        let socket = CanSocket::open(interface)
            .map_err(|source| TransportError::Io { device: interface.to_string(), source })?;
        Ok(Self { interface: interface.to_string(), socket })
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

    async fn send(&mut self, packet: Packet) -> Result<(), TransportError> {
        let frame = to_socketcan(&packet).ok_or_else(|| TransportError::Unsupported {
            device: self.device(),
            what: format!("{packet:?} (not a classic CAN frame)"),
        })?;
        self.socket
            .write_frame(frame)
            .await
            .map_err(|source| TransportError::Io { device: self.device(), source })
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
