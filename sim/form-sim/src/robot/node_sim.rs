//! A node with its fault schedule: what the bus runners drive.

use firmware_protocol::Packet;
use tokio::time::{Duration, Instant};

use crate::fault::{NodeEvent, NodeSchedule};
use crate::node::Node;

/// A simulated node and the faults that will hit it.
#[derive(Debug)]
pub(crate) struct NodeSim {
    pub node: Node,
    schedule: NodeSchedule,
    /// The start of the run (fault times count from it).
    origin: Instant,
}

impl NodeSim {
    pub fn new(node: Node, schedule: NodeSchedule, origin: Instant) -> Self {
        Self { node, schedule, origin }
    }

    fn since_origin(&self, now: Instant) -> Duration {
        now.saturating_duration_since(self.origin)
    }

    /// Whether the node is cut off the bus at `now`.
    pub fn is_silent(&self, now: Instant) -> bool {
        self.schedule.is_silent(self.since_origin(now))
    }

    /// Applies the faults due by `now`.
    fn apply_due(&mut self, now: Instant) {
        for event in self.schedule.due(self.since_origin(now)) {
            match event {
                NodeEvent::Reboot => self.node.reboot(now),
                NodeEvent::Actuator(actuator, fault) => self.node.inject(now, actuator, fault),
            }
        }
    }

    /// Lets time pass; returns what the node sends (nothing while it is silent).
    pub fn tick(&mut self, now: Instant) -> Vec<Packet> {
        self.apply_due(now);
        self.node.tick(now);
        let outgoing = self.node.take_outgoing();
        if self.is_silent(now) { Vec::new() } else { outgoing }
    }

    /// Hands the node a packet (unless it is silent); returns its answer and how much later
    /// than normal it goes out.
    pub fn receive(&mut self, now: Instant, packet: &Packet) -> (Duration, Vec<Packet>) {
        self.apply_due(now);
        if self.is_silent(now) {
            return (Duration::ZERO, Vec::new());
        }
        self.node.receive(now, packet);
        (self.schedule.reply_delay(self.since_origin(now)), self.node.take_outgoing())
    }
}
