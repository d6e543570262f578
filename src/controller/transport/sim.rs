//! The in-process simulated CAN bus (`sim::bus::can`), classic or FD: packets go through
//! `can::encode` / `can::decode` exactly as on a SocketCAN interface.

use firmware_protocol::{Link, Packet, can};
use sim::bus::can::{CanBus, CanPort};

use super::{Transport, TransportError};

/// The host's port on a simulated bus.
#[derive(Debug)]
pub struct SimBus {
    port: CanPort,
    link: Link,
}

impl SimBus {
    /// Attaches the host to `bus`.
    pub fn attach(bus: &CanBus) -> Self {
        Self { port: bus.attach(), link: bus.kind().link() }
    }
}

impl Transport for SimBus {
    fn link(&self) -> Link {
        self.link
    }

    fn device(&self) -> String {
        "simulated bus".into()
    }

    async fn send(&mut self, packet: Packet) -> Result<(), TransportError> {
        let unsupported =
            |what: String| TransportError::Unsupported { device: self.device(), what };
        let frame = can::encode(&packet).map_err(|e| unsupported(format!("{packet:?}: {e}")))?;
        if frame.is_fd() && self.link != Link::CanFd {
            return Err(unsupported(format!("{packet:?} (a CAN FD frame)")));
        }
        // Queued in order, like a write to a SocketCAN socket: the bus sends FIFO.
        self.port.queue(frame).map_err(|e| TransportError::Io {
            device: self.device(),
            source: std::io::Error::other(e.to_string()),
        })
    }

    async fn recv(&mut self) -> Result<Packet, TransportError> {
        loop {
            let frame =
                self.port.recv().await.ok_or_else(|| TransportError::Closed(self.device()))?;
            if let Ok(packet) = can::decode(&frame) {
                return Ok(packet);
            }
        }
    }
}
