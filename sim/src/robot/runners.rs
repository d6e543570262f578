//! The tasks that run nodes on a bus: one task per node on CAN (each node is its own
//! controller on the bus), one task for all nodes on a serial line (they share the line and
//! only answer the host).

use std::io;
use std::sync::{Arc, Mutex, MutexGuard, PoisonError};

use firmware_protocol::{Packet, can};
use tokio::time::{Duration, Instant, MissedTickBehavior, interval_at, sleep_until};

use super::node_sim::NodeSim;
use crate::bus::can::{CanPort, CanSender};
use crate::bus::serial::SerialLine;

/// The longest a runner may go between two wakes before the gap counts as the simulator's own
/// stall (its process descheduled on a busy machine): nodes are ticked every millisecond, so
/// this is fifty ticks missed.
const STALL: Duration = Duration::from_millis(50);

/// Tells the nodes the time beyond [`STALL`] since `last`, a stall of the simulator, and
/// returns now.
fn excuse_stall(nodes: &[SharedNode], last: Instant) -> Instant {
    let now = Instant::now();
    let gap = now.saturating_duration_since(last);
    if gap > STALL {
        for node in nodes {
            lock(node).node.excuse(gap - STALL);
        }
    }
    now
}

/// A node shared by its runner and [`SimulatedForm::state`](super::SimulatedForm::state).
pub(crate) type SharedNode = Arc<Mutex<NodeSim>>;

pub(crate) fn lock(node: &SharedNode) -> MutexGuard<'_, NodeSim> {
    node.lock().unwrap_or_else(PoisonError::into_inner)
}

/// Runs one node on a CAN port: frames in, ticks, frames out (answers of a slow node later).
pub(crate) async fn node_on_can(node: SharedNode, port: CanPort, tick: Duration, start: Instant) {
    let (sender, mut receiver) = port.split();
    let mut ticker = interval_at(start, tick);
    ticker.set_missed_tick_behavior(MissedTickBehavior::Delay);
    // Answers held back by a `slow` fault, in sending order.
    let mut delayed: Vec<(Instant, Packet)> = Vec::new();
    let mut awake = Instant::now();
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
        awake = excuse_stall(std::slice::from_ref(&node), awake);
        match woken {
            Woken::Frame(None) => return,
            Woken::Frame(Some(frame)) => {
                // Frames that are not this protocol's are not for the node.
                let Ok(packet) = can::decode(&frame) else { continue };
                let now = Instant::now();
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
                let now = Instant::now();
                let due = delayed.partition_point(|(t, _)| *t <= now);
                let packets: Vec<Packet> = delayed.drain(..due).map(|(_, p)| p).collect();
                send(&sender, &packets);
            }
            Woken::Tick => {
                let packets = lock(&node).tick(Instant::now());
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
) -> io::Result<()> {
    let mut next_tick = Instant::now();
    let mut awake = Instant::now();
    loop {
        let request = line.next_request(next_tick).await?;
        awake = excuse_stall(nodes, awake);
        match request {
            Some(request) => {
                let now = Instant::now();
                for node in nodes {
                    let (delay, answer) = lock(node).receive(now, &request.packet);
                    line.send(request.seq, &answer, delay);
                }
            }
            None => {
                let now = Instant::now();
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
