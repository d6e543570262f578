//! Faults at run time: the fate of each frame on the bus, and when each node is hit.

use std::collections::VecDeque;
use std::time::Duration;

use firmware_protocol::{Actuator, NodeId};
use rand::rngs::ChaCha8Rng;
use rand::{RngExt, SeedableRng};

use super::{BusFaults, FaultSpec, NodeFault, Window};
use crate::node::ActuatorFault;
use form_description::FormDescription;

/// What a bus fault does to one frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FrameFault {
    /// Nothing: it arrives (after the configured delay).
    None,
    /// Lost at every receiver.
    Dropped,
    /// Hit by a bit error at bit `bit` of the frame.
    Corrupted {
        /// Which bit, counted from the frame's first.
        bit: usize,
    },
}

/// Draws the bus faults of a run, frame by frame, from a seeded stream.
#[derive(Debug)]
pub struct BusFaultInjector {
    faults: BusFaults,
    rng: ChaCha8Rng,
}

impl BusFaultInjector {
    /// The bus faults of `spec`.
    pub fn new(spec: &FaultSpec) -> Self {
        Self { faults: spec.bus.clone(), rng: ChaCha8Rng::seed_from_u64(spec.seed) }
    }

    /// Whether the bus is off `t` after the start of the run.
    pub fn is_bus_off(&self, t: Duration) -> bool {
        self.faults.bus_off.iter().any(|w| w.contains(t))
    }

    /// The extra latency of every frame.
    pub fn delay(&self) -> Duration {
        self.faults.delay
    }

    /// The fate of the next frame, which has `bits` bits.
    pub fn draw(&mut self, bits: usize) -> FrameFault {
        if self.faults.drop > 0.0 && self.rng.random_range(0.0..1.0) < self.faults.drop {
            return FrameFault::Dropped;
        }
        if self.faults.corrupt > 0.0 && self.rng.random_range(0.0..1.0) < self.faults.corrupt {
            return FrameFault::Corrupted { bit: self.rng.random_range(0..bits.max(1)) };
        }
        FrameFault::None
    }
}

/// Something that happens to a node at an instant.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum NodeEvent {
    /// Its controller restarts.
    Reboot,
    /// One of its actuators breaks.
    Actuator(Actuator, ActuatorFault),
}

/// The faults of one node over a run: events at instants, and windows of silence and slow
/// answers.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct NodeSchedule {
    /// Pending events, earliest first.
    events: VecDeque<(Duration, NodeEvent)>,
    silent: Vec<Window>,
    slow: Vec<(Duration, Window)>,
}

impl NodeSchedule {
    /// The faults `spec` gives `node` of `form` (actuators are found by id in the form).
    pub fn for_node(spec: &FaultSpec, form: &FormDescription, node: NodeId) -> Self {
        let mut schedule = Self::default();
        let mut events = Vec::new();
        for n in spec.nodes.iter().filter(|n| n.node == node.get()) {
            match n.fault {
                NodeFault::Reboot => events.push((n.window.from, NodeEvent::Reboot)),
                NodeFault::Silent => schedule.silent.push(n.window),
                NodeFault::Slow(delay) => schedule.slow.push((delay, n.window)),
            }
        }
        for a in &spec.actuators {
            if let Some((at_node, actuator)) = form.locate(&a.actuator)
                && at_node == node
            {
                events.push((a.at, NodeEvent::Actuator(actuator, a.fault)));
            }
        }
        // Stable: events at the same instant keep the spec's order.
        events.sort_by_key(|(at, _)| *at);
        schedule.events = events.into();
        schedule
    }

    /// The events due by `t` (from the start of the run), in order; each is returned once.
    pub fn due(&mut self, t: Duration) -> Vec<NodeEvent> {
        let mut due = Vec::new();
        while let Some(&(at, event)) = self.events.front() {
            if at > t {
                break;
            }
            self.events.pop_front();
            due.push(event);
        }
        due
    }

    /// Whether the node is cut off the bus at `t`.
    pub fn is_silent(&self, t: Duration) -> bool {
        self.silent.iter().any(|w| w.contains(t))
    }

    /// How much later than normal the node answers at `t`.
    pub fn reply_delay(&self, t: Duration) -> Duration {
        self.slow.iter().filter(|(_, w)| w.contains(t)).map(|(d, _)| *d).max().unwrap_or_default()
    }
}
