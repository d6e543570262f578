//! The in-process simulated CAN bus (`form_sim::bus::can`), classic or FD: packets go through
//! `can::encode` / `can::decode` exactly as on a SocketCAN interface.

use firmware_protocol::{Link, Packet, can};
use form_sim::bus::can::{CanBus, CanReceiver, CanSender};

use super::gate::{Gate, PacketSink};
use super::{Transport, TransportError};

/// The name of the simulated link in messages.
const DEVICE: &str = "simulated bus";

/// The host's port on a simulated bus.
#[derive(Debug)]
pub struct SimBus {
    receiver: CanReceiver,
    gate: Gate,
    link: Link,
}

/// The sending half of the host's port.
struct Queue {
    sender: CanSender,
    link: Link,
}

impl PacketSink for Queue {
    fn write(&mut self, packet: &Packet) -> Result<(), TransportError> {
        let unsupported = |what: String| TransportError::Unsupported {
            device: DEVICE.into(),
            what: format!("{} ({what})", packet.message.code().name()),
        };
        let frame = can::encode(packet).map_err(|e| unsupported(e.to_string()))?;
        if frame.is_fd() && self.link != Link::CanFd {
            return Err(unsupported("a CAN FD frame".into()));
        }
        // Queued in order, like a write to a SocketCAN socket: the bus sends FIFO.
        self.sender.queue(frame).map_err(|e| TransportError::Io {
            device: DEVICE.into(),
            source: std::io::Error::other(e.to_string()),
        })
    }
}

impl SimBus {
    /// Attaches the host to `bus`.
    pub fn attach(bus: &CanBus) -> Self {
        let link = bus.kind().link();
        let (sender, receiver) = bus.attach().split();
        Self { receiver, gate: Gate::new(DEVICE, Queue { sender, link }), link }
    }
}

impl Transport for SimBus {
    fn link(&self) -> Link {
        self.link
    }

    fn device(&self) -> String {
        DEVICE.into()
    }

    fn gate(&self) -> &Gate {
        &self.gate
    }

    async fn recv(&mut self) -> Result<Packet, TransportError> {
        loop {
            let frame =
                self.receiver.recv().await.ok_or_else(|| TransportError::Closed(self.device()))?;
            if let Ok(packet) = can::decode(&frame) {
                return Ok(packet);
            }
        }
    }
}
