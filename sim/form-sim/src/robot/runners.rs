//! The tasks that run nodes on a bus: one task per node on CAN (each node is its own
//! controller on the bus), one task for all nodes on a serial line (they share the line and
//! only answer the host).
//!
//! **Stalls are not host silence.** A real node's watchdog runs on its own microcontroller
//! behind a wire that never pauses. Here two things can pause that a wire does not, and the
//! nodes' watchdogs leave both out ([`Stalls`]): the simulator itself (its process
//! descheduled on a busy machine), and the pseudo-terminal the host talks through (the
//! kernel holding its bytes, measured with a [`Canary`]). Each counts beyond [`STALL`].
//!
//! A wake's work runs at the instant its stall was measured ([`Stalls::excuse`] returns it):
//! a process stopped in between (SIGSTOP, or descheduled right after the canary's system
//! calls) would otherwise tick the watchdog at an instant after a stall not yet excused, and
//! latch a host timeout no wire causes; the next wake excuses that stall instead.

use std::io;
use std::sync::{Arc, Mutex, MutexGuard, PoisonError};

use firmware_protocol::{Packet, can};
use tokio::time::{Duration, Instant, MissedTickBehavior, interval_at, sleep_until};

use super::node_sim::NodeSim;
use crate::bus::can::{CanPort, CanSender};
use crate::bus::pty::Canary;
use crate::bus::serial::SerialLine;

/// The longest a runner may go between two wakes, or the kernel may hold a pty's bytes,
/// before the excess counts as a stall: nodes are ticked every millisecond, so this is fifty
/// ticks missed (and a sixth of the 300 ms watchdog).
const STALL: Duration = Duration::from_millis(50);

/// The host's pseudo-terminal's [`Canary`], shared by the runners of one served form.
pub(crate) type SharedCanary = Arc<Mutex<Canary>>;

/// One runner's account of stalls (see the module docs).
pub(crate) struct Stalls {
    awake: Instant,
    canary: Option<SharedCanary>,
    /// The part of the canary's current lag already excused.
    excused_lag: Duration,
}

impl Stalls {
    pub(crate) fn new(canary: Option<SharedCanary>) -> Self {
        Self { awake: Instant::now(), canary, excused_lag: Duration::ZERO }
    }

    /// At a wake of the runner: tells `nodes` the stall since the last wake, the runner's
    /// own or the link's (the larger: they overlap), beyond [`STALL`]. Returns the instant
    /// measured, at which the wake's work is to be done (see the module docs).
    fn excuse(&mut self, nodes: &[SharedNode]) -> Instant {
        let now = Instant::now();
        let own = now.saturating_duration_since(self.awake).saturating_sub(STALL);
        self.awake = now;
        let lag = self.canary.as_ref().map_or(Duration::ZERO, |c| lock(c).lag(now));
        let link_total = lag.saturating_sub(STALL);
        let link = link_total.saturating_sub(self.excused_lag);
        self.excused_lag = link_total;
        let lost = own.max(link);
        if !lost.is_zero() {
            for node in nodes {
                lock(node).node.excuse(lost);
            }
        }
        now
    }
}

/// A node shared by its runner and [`SimulatedForm::state`](super::SimulatedForm::state).
pub(crate) type SharedNode = Arc<Mutex<NodeSim>>;

pub(crate) fn lock<T>(shared: &Mutex<T>) -> MutexGuard<'_, T> {
    shared.lock().unwrap_or_else(PoisonError::into_inner)
}

/// Runs one node on a CAN port: frames in, ticks, frames out (answers of a slow node later).
pub(crate) async fn node_on_can(
    node: SharedNode,
    port: CanPort,
    tick: Duration,
    start: Instant,
    mut stalls: Stalls,
) {
    let (sender, mut receiver) = port.split();
    let mut ticker = interval_at(start, tick);
    ticker.set_missed_tick_behavior(MissedTickBehavior::Delay);
    // Answers held back by a `slow` fault, in sending order.
    let mut delayed: Vec<(Instant, Packet)> = Vec::new();
    loop {
        let next_delayed = delayed.first().map(|(at, _)| *at);
        let woken = tokio::select! {
            biased;
            frame = receiver.recv() => Woken::Frame(frame),
            () = sleep_until(next_delayed.unwrap_or(start)), if next_delayed.is_some() => {
                Woken::Delayed
            }
            _ = ticker.tick() => Woken::Tick,
        };
        let now = stalls.excuse(std::slice::from_ref(&node));
        match woken {
            Woken::Frame(None) => return,
            Woken::Frame(Some(frame)) => {
                // Frames that are not this protocol's are not for the node.
                let Ok(packet) = can::decode(&frame) else { continue };
                let (delay, answer) = lock(&node).receive(now, &packet);
                if delay.is_zero() {
                    send(&sender, &answer);
                } else {
                    let at = now + delay;
                    let index = delayed.partition_point(|(t, _)| *t <= at);
                    delayed.splice(index..index, answer.into_iter().map(|p| (at, p)));
                }
            }
            Woken::Delayed => {
                let due = delayed.partition_point(|(t, _)| *t <= now);
                let packets: Vec<Packet> = delayed.drain(..due).map(|(_, p)| p).collect();
                send(&sender, &packets);
            }
            Woken::Tick => {
                let packets = lock(&node).tick(now);
                send(&sender, &packets);
            }
        }
    }
}

/// What woke a node's runner.
enum Woken {
    Frame(Option<firmware_protocol::can::Frame>),
    Delayed,
    Tick,
}

fn send(sender: &CanSender, packets: &[Packet]) {
    for packet in packets {
        if let Ok(frame) = can::encode(packet) {
            // A frame lost to bus-off is lost, as on a real bus.
            let _ = sender.queue(frame);
        }
    }
}

/// Runs all nodes on a serial line: every request goes to every node (each keeps what is
/// addressed to it or broadcast); the addressed node's answer goes back with the request's
/// sequence number.
pub(crate) async fn nodes_on_serial(
    nodes: &[SharedNode],
    line: &mut SerialLine,
    tick: Duration,
    mut stalls: Stalls,
) -> io::Result<()> {
    let mut next_tick = Instant::now();
    loop {
        let request = line.next_request(next_tick).await?;
        let now = stalls.excuse(nodes);
        match request {
            Some(request) => {
                for node in nodes {
                    let (delay, answer) = lock(node).receive(now, &request.packet);
                    line.send(request.seq, &answer, delay);
                }
            }
            None => {
                for node in nodes {
                    // Serial nodes never speak unasked: a tick sends nothing.
                    lock(node).tick(now);
                }
                next_tick += tick;
                if next_tick <= now {
                    next_tick = now + tick;
                }
            }
        }
    }
}
