//! A minimal host for the simulated form's tests: sends packets on an in-process CAN bus,
//! keeps what it receives, sends host heartbeats when asked to. (The real host controller is
//! the root package's; these tests check the simulator, not it.)

#![allow(dead_code)] // Each test file uses its own part of it.

use firmware_protocol::drive::{DriveCommand, DriveState};
use firmware_protocol::message::{Heartbeat, HostHeartbeat};
use firmware_protocol::{
    ActuatorSet, Message, NodeId, PROTOCOL_VERSION, Packet, ProtocolVersion, can,
};
use form_sim::bus::can::{CanBus, CanPort};
use tokio::time::{Duration, Instant, sleep_until};

pub const HEARTBEAT_PERIOD: Duration = Duration::from_millis(100);

/// A host on the bus.
pub struct TestHost {
    port: CanPort,
    /// Everything received, with the bus time it arrived.
    pub received: Vec<(Instant, Packet)>,
    /// Send a host heartbeat every 100 ms while running.
    pub heartbeats: bool,
    /// The protocol version its heartbeats announce (default this crate's).
    pub protocol: ProtocolVersion,
    next_heartbeat: Instant,
}

pub fn node(id: u8) -> NodeId {
    NodeId::new(id).unwrap()
}

pub fn host_heartbeat() -> Message {
    Message::HostHeartbeat(HostHeartbeat { protocol: PROTOCOL_VERSION })
}

impl TestHost {
    pub fn attach(bus: &CanBus) -> Self {
        Self {
            port: bus.attach(),
            received: Vec::new(),
            heartbeats: false,
            protocol: PROTOCOL_VERSION,
            next_heartbeat: Instant::now(),
        }
    }

    /// Sends a packet and waits until it has crossed the bus.
    pub async fn send(&self, packet: Packet) {
        self.port.send(can::encode(&packet).unwrap()).await.unwrap();
    }

    /// Queues packets, in order, without waiting.
    pub fn queue(&self, packets: impl IntoIterator<Item = Packet>) {
        for packet in packets {
            self.port.queue(can::encode(&packet).unwrap()).unwrap();
        }
    }

    /// Receives (and sends heartbeats, if on) for `duration`.
    pub async fn run_for(&mut self, duration: Duration) {
        let end = Instant::now() + duration;
        self.run_until(end, |_| false).await;
    }

    /// Receives until `done` holds for what was received, or `deadline`; returns whether
    /// `done` held.
    pub async fn run_until(
        &mut self,
        deadline: Instant,
        mut done: impl FnMut(&[(Instant, Packet)]) -> bool,
    ) -> bool {
        loop {
            if done(&self.received) {
                return true;
            }
            let now = Instant::now();
            if now >= deadline {
                return false;
            }
            if self.heartbeats && now >= self.next_heartbeat {
                let heartbeat = HostHeartbeat { protocol: self.protocol };
                self.queue([Packet::broadcast(Message::HostHeartbeat(heartbeat))]);
                self.next_heartbeat = now + HEARTBEAT_PERIOD;
            }
            let wake = if self.heartbeats { deadline.min(self.next_heartbeat) } else { deadline };
            tokio::select! {
                biased;
                received = self.port.recv_timed() => {
                    let received = received.expect("the bus closed");
                    if let Ok(packet) = can::decode(&received.frame) {
                        self.received.push((received.at, packet));
                    }
                }
                () = sleep_until(wake) => {}
            }
        }
    }

    /// Forgets what was received.
    pub fn clear(&mut self) {
        self.received.clear();
    }

    /// The last heartbeat of every node in `nodes`, if each sent one.
    pub fn last_heartbeats(&self, nodes: &[NodeId]) -> Option<Vec<Heartbeat>> {
        nodes.iter().map(|&n| last_heartbeat(&self.received, n)).collect()
    }

    /// Heartbeats on, Enable and Home every actuator of `nodes` (broadcast); waits until all
    /// are Enabled and homed.
    pub async fn enable_and_home(&mut self, nodes: &[NodeId]) {
        self.heartbeats = true;
        self.run_for(Duration::from_millis(5)).await;
        self.send(Packet::broadcast(Message::Control(DriveCommand::Enable))).await;
        self.send(Packet::broadcast(Message::Home(ActuatorSet::ALL))).await;
        let deadline = Instant::now() + Duration::from_secs(5);
        let all_homed = |received: &[(Instant, Packet)]| {
            nodes.iter().all(|&n| {
                last_heartbeat(received, n)
                    .is_some_and(|h| h.state == DriveState::Enabled && h.homed == ActuatorSet::ALL)
            })
        };
        let homed = self.run_until(deadline, all_homed).await;
        let events: Vec<_> = self
            .received
            .iter()
            .filter(|(_, p)| matches!(p.message, Message::Emergency(_)))
            .map(|(at, p)| (at.elapsed(), p))
            .collect();
        assert!(
            homed,
            "the nodes did not all home: {:?}, events {events:?}",
            self.last_heartbeats(nodes)
        );
    }
}

/// The last heartbeat `node` sent among `received`.
pub fn last_heartbeat(received: &[(Instant, Packet)], node: NodeId) -> Option<Heartbeat> {
    received.iter().rev().find_map(|(_, p)| match p.message {
        Message::Heartbeat(h) if p.address == firmware_protocol::Address::Node(node) => Some(h),
        _ => None,
    })
}
