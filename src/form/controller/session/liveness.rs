//! Liveness both ways: the host keeps the nodes' watchdogs fed, and judges the nodes' silence
//! without blaming them for its own or the link's stalls. Implements "Timing on a busy host"
//! and "The pseudo-terminal's own stalls" of `docs/controller-and-safety.md`, on the periods of
//! `firmware-protocol/README.md` ("Timing").
//!
//! * host heartbeats: on CAN a broadcast `HostHeartbeat` every 100 ms; on serial, where nodes
//!   speak only when polled, an addressed `HostHeartbeat` to every node in turn every 20 ms
//!   (the poll is the heartbeat);
//!   and, on every link, a broadcast `HostHeartbeat` whenever one is due while the session
//!   waits for an answer (so a long series of requests never starves a node's watchdog);
//! * an unanswered request or poll round tells nothing about the nodes when the link itself
//!   stalled meanwhile — the host's own write slept in the kernel longer than an answer may
//!   take, or the whole link carried nothing (on serial a poll of another node goes with
//!   every request, so that a working link always carries something): such an exchange
//!   does not count, for up to [`LINK_STALL_LIMIT`] in a row ([`Session::silence_counts`]);
//! * a node that misses three heartbeats in a row is lost. On CAN, where nodes send them
//!   unasked, that is [`NODE_LOST_AFTER`] of *listening time*: silence counts only while the
//!   host's receive loop actually runs ([`ListeningClock`]), so a host descheduled by a busy
//!   machine does not blame healthy nodes for its own stall. On serial, where the poll is the
//!   heartbeat, it is [`POLLS_LOST`] polls in a row unanswered: a host that polls slowly (busy,
//!   or behind a slow adapter) does not make a node that answers every poll silent. Received
//!   packets are always taken before silence is judged;
//! * a node's silence is told from the link's: every time the whole link carried nothing for
//!   more than [`LINK_QUIET`] (on CAN every node speaks every 20 ms) is the link's stall, and
//!   the session remembers them, so a node's silence leaves out every stall after its last
//!   packet — also once the link talks again, whichever node is heard first (the session used
//!   to excuse only a stall still going on, and after a stall of 0.5 s the first node heard
//!   made the others lost). A stall longer than [`LINK_STALL_LIMIT`] is an error of its own,
//!   [`SessionError::LinkStalled`], on every link: the adapter, cable or bus stopped, not a
//!   node. One node quiet while the others talk is lost after [`NODE_LOST_AFTER`], as ever.

use std::time::Duration;

use firmware_protocol::message::HostHeartbeat;
use firmware_protocol::{Address, Link, Message, NodeId, PROTOCOL_VERSION, Packet, timing};
use tokio::time::Instant;

use super::requests::answer_timeout;
use super::{Session, SessionError};
use crate::form::controller::transport::Transport;

/// The host heartbeat period on CAN.
pub const HEARTBEAT_PERIOD: Duration =
    Duration::from_millis(timing::HOST_HEARTBEAT_PERIOD_MS as u64);
/// The poll period on serial.
pub const POLL_PERIOD: Duration = Duration::from_millis(timing::FEEDBACK_PERIOD_MS as u64);
/// A node not heard for this long is lost (three heartbeat periods).
pub const NODE_LOST_AFTER: Duration = Duration::from_millis(timing::NODE_LOST_AFTER_MS as u64);
/// A serial node that leaves this many polls in a row unanswered is lost: the poll is its
/// heartbeat, and [`NODE_LOST_AFTER`] is this many heartbeat periods.
pub const POLLS_LOST: u32 = (timing::NODE_LOST_AFTER_MS / timing::HEARTBEAT_PERIOD_MS) as u32;
/// How long the whole link may carry nothing before its silence is blamed on the nodes (CAN)
/// or requests time out regardless: the longest stall of a pseudo-terminal measured on a
/// loaded 2-core machine (1.3 s, the kernel holding every pty's bytes; see the simulator's `bus/pty.rs`),
/// with margin. A single silent node is still found within [`NODE_LOST_AFTER`], since the
/// others keep talking.
pub const LINK_STALL_LIMIT: Duration = Duration::from_secs(2);
/// On CAN, the link carrying nothing at all for longer than this (two feedback periods of
/// every node) is the link's stall, not the nodes' silence.
const LINK_QUIET: Duration = Duration::from_millis(2 * timing::FEEDBACK_PERIOD_MS as u64);
/// The longest a gap between two wakes of the receive loop counts towards a node's silence:
/// the loop wakes at least every answer timeout (60 ms on serial), so a longer gap is the
/// host's own stall (one heartbeat period allows for a busy machine).
pub const LONGEST_COUNTED_GAP: Duration = HEARTBEAT_PERIOD;

/// Time in which the host was listening: wall time, except that a gap between two wakes of
/// the receive loop longer than [`LONGEST_COUNTED_GAP`] (the process was descheduled) counts
/// only that much.
#[derive(Clone, Copy, Debug)]
pub struct ListeningClock {
    listened: Duration,
    last: Instant,
}

impl ListeningClock {
    pub(super) fn new() -> Self {
        Self { listened: Duration::ZERO, last: Instant::now() }
    }

    /// Counts the time since the last tick; returns the listening time now.
    pub(super) fn tick(&mut self) -> Duration {
        let now = Instant::now();
        self.listened += now.saturating_duration_since(self.last).min(LONGEST_COUNTED_GAP);
        self.last = now;
        self.listened
    }
}

/// How much of a whole-link silence of `quiet` was the link's stall: all of it once longer
/// than [`LINK_QUIET`], up to [`LINK_STALL_LIMIT`] (beyond that the link is reported stalled).
fn stall_part(quiet: Duration) -> Duration {
    if quiet > LINK_QUIET { quiet.min(LINK_STALL_LIMIT) } else { Duration::ZERO }
}

impl<T: Transport> Session<T> {
    /// A broadcast host heartbeat when one is due (on serial, between polls too).
    pub(super) async fn keep_alive(&mut self) -> Result<(), SessionError> {
        let now = Instant::now();
        if now >= self.next_heartbeat {
            self.next_heartbeat = now + HEARTBEAT_PERIOD;
            let heartbeat = Message::HostHeartbeat(HostHeartbeat { protocol: PROTOCOL_VERSION });
            self.send(Packet::broadcast(heartbeat)).await?;
        }
        Ok(())
    }

    /// Host heartbeats (CAN) or polls (serial) when due.
    pub(super) async fn service(&mut self) -> Result<(), SessionError> {
        let now = Instant::now();
        if now < self.next_service {
            return Ok(());
        }
        if self.link() == Link::Serial {
            self.next_service = now + POLL_PERIOD;
            let heartbeat = Message::HostHeartbeat(HostHeartbeat { protocol: PROTOCOL_VERSION });
            let nodes: Vec<NodeId> = self.nodes.keys().copied().collect();
            let heard = self.heard_count;
            let mut slowest_write = Duration::ZERO;
            let mut unanswered = Vec::new();
            for node in nodes {
                // A lost poll is noticed by liveness, not retried.
                let deadline = Instant::now() + answer_timeout(Link::Serial);
                slowest_write =
                    slowest_write.max(self.timed_send(Packet::node(node, heartbeat)).await?);
                let answer = self
                    .receive_until(deadline, |p| {
                        p.address == Address::Node(node)
                            && matches!(p.message, Message::AllFeedback(_))
                    })
                    .await?;
                if answer.is_none() {
                    unanswered.push(node);
                }
            }
            // A round in which the link stalled tells nothing about the nodes.
            if !unanswered.is_empty() && self.silence_counts(heard, slowest_write) {
                for node in unanswered {
                    if let Some(status) = self.nodes.get_mut(&node) {
                        // Any packet from the node starts the count again (see `handle`).
                        status.unanswered_polls += 1;
                    }
                }
            }
        } else {
            self.next_service = now + HEARTBEAT_PERIOD;
            self.next_heartbeat = now;
            self.keep_alive().await?;
        }
        Ok(())
    }

    /// The link carried a packet from a described node at listening time `now`: the
    /// whole-link silence it ends, if longer than [`LINK_QUIET`], was the link's stall (see
    /// [`Session::excused`]); one longer than [`LINK_STALL_LIMIT`] is kept for
    /// [`Session::lost`] to report.
    pub(super) fn link_heard(&mut self, now: Duration) {
        if self.heard_count > 0 {
            let quiet = now.saturating_sub(self.heard_any);
            self.ended_stalls += stall_part(quiet);
            if quiet > LINK_STALL_LIMIT {
                self.overlong_stall.get_or_insert(quiet);
            }
        }
        self.heard_any = now;
        self.heard_count += 1;
    }

    /// How long the whole link has carried nothing from any node at listening time `now`
    /// (zero before it carried anything).
    fn link_quiet(&self, now: Duration) -> Duration {
        if self.heard_count == 0 { Duration::ZERO } else { now.saturating_sub(self.heard_any) }
    }

    /// The link's stalls up to listening time `now`, the one going on included: the time the
    /// whole link carried nothing for longer than [`LINK_QUIET`], each stall counted up to
    /// [`LINK_STALL_LIMIT`]. A node's silence leaves out what this grew by since it was last
    /// heard ([`NodeStatus::excused_at`]), whichever node the link carried first afterwards.
    pub(super) fn excused(&self, now: Duration) -> Duration {
        self.ended_stalls + stall_part(self.link_quiet(now))
    }

    /// Whether an exchange that went unanswered counts against the nodes, given the packets
    /// heard before it began and how long the host's write of it took. It does not while the
    /// link is stalled (the write slept in the kernel longer than an answer may take, or
    /// nothing at all was heard meanwhile: on a loaded machine the tty layer can hold every
    /// pty's bytes for a second, see the simulator's `bus/pty.rs`), for up to [`LINK_STALL_LIMIT`] in a
    /// row: a dead link, or a host whose every write sleeps, is still reported.
    pub(super) fn silence_counts(&mut self, heard_before: u64, wrote_for: Duration) -> bool {
        let stalled = wrote_for > answer_timeout(self.link()) || self.heard_count == heard_before;
        if !stalled {
            self.stalled_since = None;
            return true;
        }
        let now = Instant::now();
        let since = *self.stalled_since.get_or_insert(now);
        now.saturating_duration_since(since) > LINK_STALL_LIMIT
    }

    /// On serial, where nodes speak only when asked, polls a node other than `node` (the one
    /// heard last): its answer shows whether the link carried anything while `node` was
    /// asked something (see [`Session::silence_counts`]). On CAN the nodes speak unasked.
    pub(super) async fn poll_witness(&mut self, node: NodeId) -> Result<(), SessionError> {
        if self.link() != Link::Serial {
            return Ok(());
        }
        let witness = self.nodes.iter().filter(|(n, _)| **n != node).max_by_key(|(_, s)| s.heard);
        if let Some((&witness, _)) = witness {
            let heartbeat = Message::HostHeartbeat(HostHeartbeat { protocol: PROTOCOL_VERSION });
            self.send(Packet::node(witness, heartbeat)).await?;
        }
        Ok(())
    }

    /// The link stalled, or the first node lost (see the module docs): on every link, nothing
    /// heard from any node for longer than [`LINK_STALL_LIMIT`] (going on, or ended since the
    /// last look) is the link's stall; on serial, a node that left [`POLLS_LOST`] polls in a
    /// row unanswered is lost; on CAN, one not heard for [`NODE_LOST_AFTER`] of listening time,
    /// the link's stalls since its last packet left out ([`Session::excused`]: on CAN every
    /// node speaks every 20 ms, so the whole link quiet is the link's stall — a busy host's tty
    /// layer holding every byte, a stopped adapter — while one node quiet among talking ones
    /// is that node's silence).
    pub(super) fn lost(&mut self) -> Option<SessionError> {
        let now = self.clock.tick();
        let quiet = self.link_quiet(now);
        let overlong = (quiet > LINK_STALL_LIMIT).then_some(quiet);
        if let Some(quiet) = self.overlong_stall.or(overlong) {
            return Some(SessionError::LinkStalled { quiet });
        }
        let serial = self.link() == Link::Serial;
        let excused = self.excused(now);
        self.nodes.iter().find_map(|(&node, status)| {
            let stalled = excused.saturating_sub(status.excused_at);
            let silent = now.saturating_sub(status.heard?).saturating_sub(stalled);
            let node = node.get();
            if serial {
                (status.unanswered_polls >= POLLS_LOST)
                    .then_some(SessionError::NodeUnanswered { node, silent })
            } else {
                (silent > NODE_LOST_AFTER).then_some(SessionError::NodeLost { node, silent })
            }
        })
    }
}
