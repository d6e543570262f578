//! Addressed requests (`IdentifyRequest`, `Control`, `Home`) and their answers: each is sent up
//! to [`ATTEMPTS`] times on no answer, until its node has sent every answer the code table
//! names for it; an `Ack` other than Ok is an error naming the node, worded from a fresh
//! heartbeat. An attempt made while the link stalled does not count (see `liveness.rs`).
//! Implements the retry rule of `firmware-protocol/README.md` ("Timing": the host retries
//! twice, then reports the node), with two attempts more for a lossy bus.

use std::time::Duration;

use firmware_protocol::drive::{AckStatus, DriveCommand};
use firmware_protocol::{Address, Link, Message, NodeId, Packet, timing};
use tokio::time::Instant;

use super::{Session, SessionError};
use crate::form::controller::faults;
use crate::form::controller::transport::Transport;

/// How many times a request is sent before its node is reported: the protocol's two
/// retries ([`timing::RETRIES`]), plus two more so that a lossy bus (5 % of frames lost each
/// way) does not fail a whole session on one node's bad luck.
pub const ATTEMPTS: u8 = timing::RETRIES + 3;

/// A request's name for people: a drive command's own name (`Enable`), else its code's.
fn request_name(request: &Message) -> &'static str {
    match request {
        Message::Control(DriveCommand::Disable) => "Disable",
        Message::Control(DriveCommand::Enable) => "Enable",
        Message::Control(DriveCommand::FaultReset) => "FaultReset",
        Message::Control(DriveCommand::Halt) => "Halt",
        other => other.code().name(),
    }
}

/// How long to wait for an answer on a serial link before retrying: a pseudo-terminal or a
/// USB adapter on a busy host answers in a few ms, plus the node's poll cycle; lenient.
const SERIAL_ANSWER_TIMEOUT: Duration = Duration::from_millis(60);
/// The same on CAN, where a node answers as soon as the frame arrives (1 Mbit/s: a frame
/// takes about 0.13 ms); lenient for a busy host.
const CAN_ANSWER_TIMEOUT: Duration = Duration::from_millis(30);

/// How long to wait for an answer before retrying.
pub(super) fn answer_timeout(link: Link) -> Duration {
    match link {
        Link::Serial => SERIAL_ANSWER_TIMEOUT,
        _ => CAN_ANSWER_TIMEOUT,
    }
}

impl<T: Transport> Session<T> {
    /// Sends `packet` and returns how long the write took (it can sleep in the kernel).
    pub(super) async fn timed_send(&mut self, packet: Packet) -> Result<Duration, SessionError> {
        let start = Instant::now();
        self.send(packet).await?;
        Ok(start.elapsed())
    }

    /// Sends `packet` (addressed to `node`) until its node has sent every answer the code
    /// table names for it ([`Code::answers`]), or an `Ack` naming it; up to
    /// [`ATTEMPTS`] times (attempts while the link stalls do not count). Returns the last
    /// answer.
    pub(super) async fn request(&mut self, packet: Packet) -> Result<Message, SessionError> {
        let node = match packet.address {
            Address::Node(n) => n,
            Address::Broadcast => NodeId::MIN,
        };
        let request = packet.message;
        // What is still awaited; an answer heard in an earlier attempt counts.
        let mut awaited = request.code().answers().to_vec();
        let attempts = ATTEMPTS;
        let mut made = 0;
        while made < attempts {
            let heard = self.heard_count;
            let wrote_for = self.timed_send(packet).await?;
            self.poll_witness(node).await?;
            let deadline = Instant::now() + answer_timeout(self.link());
            let answer = self
                .receive_until(deadline, |p| {
                    if p.address != Address::Node(node) || !p.message.answers(&request) {
                        return false;
                    }
                    awaited.retain(|&code| code != p.message.code());
                    awaited.is_empty() || matches!(p.message, Message::Ack(_))
                })
                .await?;
            if let Some(answer) = answer {
                self.stalled_since = None;
                return Ok(answer.message);
            }
            if self.silence_counts(heard, wrote_for) {
                made += 1;
            }
        }
        Err(SessionError::NoAnswer { node: node.get(), request: request_name(&request), attempts })
    }

    /// Sends a `Control` command to `node` and checks its `Ack`.
    pub async fn control(
        &mut self,
        node: NodeId,
        command: DriveCommand,
    ) -> Result<(), SessionError> {
        let message = Message::Control(command);
        let answer = self.request(Packet::node(node, message)).await?;
        self.expect_ok(node, request_name(&message), answer).await
    }

    /// Checks a request's `Ack`; a refusal names the node's state and faults as a fresh
    /// heartbeat shows them (the last one known may be from before the request: on serial,
    /// from the poll before it — a node that latched a fault meanwhile would be misreported
    /// as Disabled).
    pub(super) async fn expect_ok(
        &mut self,
        node: NodeId,
        name: &'static str,
        answer: Message,
    ) -> Result<(), SessionError> {
        match answer {
            Message::Ack(ack) if ack.status == AckStatus::Ok => Ok(()),
            Message::Ack(ack) => {
                // Only an e-stop outranks the refusal; without a fresh heartbeat the hint
                // uses the last one.
                if let Err(stopped @ SessionError::Stopped(_)) = self.refresh().await {
                    return Err(stopped);
                }
                let hint = match self.nodes.get(&node).and_then(|s| s.heartbeat) {
                    Some(h) if !h.faults.is_empty() => format!(
                        " (node {}: {})",
                        faults::state_name(h.state),
                        faults::describe(h.faults)
                    ),
                    Some(h) => format!(" (node {})", faults::state_name(h.state)),
                    None => String::new(),
                };
                Err(SessionError::Refused {
                    node: node.get(),
                    request: name,
                    status: ack.status,
                    hint,
                })
            }
            _ => Err(SessionError::NoAnswer { node: node.get(), request: name, attempts: 1 }),
        }
    }
}
