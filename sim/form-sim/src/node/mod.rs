//! The simulated node: the node side of `firmware-protocol` as a pure, deterministic state
//! machine, with the physical actuators it drives.
//!
//! A [`Node`] knows no bus and no clock: it is driven by [`Node::receive`] (a decoded
//! [`Packet`] at an instant) and [`Node::tick`] (time passing), and leaves the packets it
//! sends in an outbox ([`Node::take_outgoing`]). The same node therefore runs on the
//! in-process CAN bus, on a serial line and behind slcan; the `robot` module wires it up.
//! Motion is exact at any instant (piecewise-constant acceleration, see [`motion`]); the
//! tick period only decides how soon *events* are noticed (the watchdog, the home switch, a
//! following error) and when cyclic frames go out — one tick late at worst.
//!
//! **Packet handling** (the README's "Implementing a node"):
//!
//! * Only host → node messages addressed to this node or broadcast are taken; everything
//!   else (other nodes' traffic, node → host codes) is ignored. Decoding already dropped
//!   malformed frames.
//! * Answers: `Control`, `Home`, `MotionLimits` and `ParamWrite` → `Ack`; `ParamRead` →
//!   `ParamValue` (or `Ack` with the failure); `IdentifyRequest` → `Identity`, then
//!   `Capabilities`; an addressed `HostHeartbeat` (a poll) → `Heartbeat` and the positions.
//!   On serial a broadcast is never answered, and pending `Emergency` events go out after
//!   a poll's answer, oldest first (at most [`PENDING_EMERGENCIES`] are kept); on CAN they
//!   go out when they happen, with a `Heartbeat` at power-on and on every state change, and
//!   heartbeat and feedback every `HeartbeatPeriod` / `FeedbackPeriod`.
//! * Set-points stage targets; `Sync` starts every staged move at once, lasting the SYNC's
//!   duration (0: each as fast as it can). A move in progress is retargeted from its current
//!   position and velocity.
//!
//! **Safety rules** — the node never moves outside what it was allowed:
//!
//! * A target outside the soft limits (by default the stroke) is refused with a
//!   `TargetOutOfRange` event and clears that actuator's staged target; it is never
//!   executed. A target for an actuator that is not homed is refused with `NotHomed`.
//! * Every move, brake and homing stays within the actuator's speed and acceleration limits;
//!   a SYNC duration too short for them moves at the limits, arrives late and reports
//!   `DurationTooShort` with the shortest feasible duration, computed with the protocol's
//!   `update::shortest_duration_ms` (from rest).
//! * Moves need the power stage (Enabled); `Enable` needs a host heartbeat of the same major
//!   version within the watchdog timeout.
//! * The watchdog: in Enabled or Homing, more than `WatchdogTimeout` (300 ms) without a host
//!   heartbeat latches `HOST_TIMEOUT`. Like every fault and `EmergencyStop`, it stops every
//!   actuator at its acceleration limit, turns the power stage off, drops staged targets and
//!   sends `Emergency`.
//! * A node of protocol 1.1 measures each actuator's load (what a garment presses on its
//!   panel, [`Node::apply_load`]) and reports it with the feedback to a 1.1 host; an
//!   actuator whose load is over its `ForceLimit` stalls where it is and the node latches
//!   `OVER_FORCE`. A 1.0 node measures nothing.
//! * A panel lagging its plan by more than `FollowingErrorLimit` (a jam) latches
//!   `FOLLOWING_ERROR` and forgets that actuator's home; so does a broken encoder, whose
//!   cause remains until the encoder works again, so `FaultReset` is refused.
//!
//! **Homing** creeps each actuator towards its home end at `HomingSpeed` until the home
//! switch (at position 0) closes, brakes, and returns to 0. At power-on the panels are
//! wherever they were (`ActuatorConfig::start_mm`), unknown to the node.

mod actuator;
pub mod motion;
mod params;

pub use actuator::{ActuatorConfig, ActuatorFault, ENCODER_GLITCH_MM};

use std::collections::VecDeque;

use firmware_protocol::actuator::MAX_ACTUATORS;
use firmware_protocol::drive::{AckStatus, DriveCommand, DriveState, EmergencyCode, Faults};
use firmware_protocol::message::{
    Ack, Capabilities, Direction, Emergency, Forces8, Half, Heartbeat, Identity, MotionLimits,
    Param, Positions8,
};
use firmware_protocol::version::FirmwareVersion;
use firmware_protocol::{
    Accel, Actuator, ActuatorSet, Address, Code, Force, HUNDREDTHS_PER_MM, HUNDREDTHS_PER_N, Link,
    Message, NodeId, Packet, Position, ProtocolVersion, Speed,
};
use rand::SeedableRng;
use rand::rngs::ChaCha8Rng;
use rand_distr::{Distribution, Normal};
use tokio::time::{Duration, Instant};

use actuator::ActuatorSim;
use params::NodeParams;

/// How many `Emergency` events a serial node keeps for the next poll (older ones are lost).
pub const PENDING_EMERGENCIES: usize = 32;

/// Position noise is clipped at this many standard deviations.
const NOISE_CLIP: f64 = 4.0;

/// What a simulated node is.
#[derive(Clone, Debug, PartialEq)]
pub struct NodeConfig {
    /// Its bus address.
    pub id: NodeId,
    /// The link it is on: which feedback messages it sends, and whether it speaks unasked.
    pub link: Link,
    /// Its actuators, 1..=8, by index (more than 8 are ignored).
    pub actuators: Vec<ActuatorConfig>,
    /// The firmware version it reports.
    pub firmware: FirmwareVersion,
    /// Standard deviation of the position noise in feedback, mm (0 = none).
    pub noise_mm: f64,
    /// Standard deviation of the force sensors' noise, N (0 = none).
    pub force_noise_n: f64,
    /// The protocol version it speaks: 1.0 nodes measure no force.
    pub protocol: ProtocolVersion,
    /// Seed of the noise.
    pub seed: u64,
}

/// The truth about one actuator, for tests and displays (a real host only sees feedback).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ActuatorState {
    /// Where the panel is, mm from home.
    pub position_mm: f64,
    /// Its velocity, mm/s.
    pub velocity_mm_s: f64,
    /// The node knows its home.
    pub homed: bool,
    /// Moving or homing, as the heartbeat reports.
    pub moving: bool,
    /// The target waiting for SYNC.
    pub staged: Option<Position>,
    /// The mechanism is jammed.
    pub stalled: bool,
    /// The encoder is broken.
    pub encoder_fault: bool,
    /// The external load on the panel, N, positive inwards.
    pub load_n: f64,
    /// Its force limit, N.
    pub force_limit_n: f64,
}

/// A draw of `normal` (a sensor's noise of standard deviation `sd`) clipped at
/// [`NOISE_CLIP`] standard deviations; 0 without noise.
fn clipped(normal: &Option<Normal<f64>>, sd: f64, rng: &mut ChaCha8Rng) -> f64 {
    match normal {
        Some(normal) => normal.sample(rng).clamp(-NOISE_CLIP * sd, NOISE_CLIP * sd),
        None => 0.0,
    }
}

/// A simulated node and its actuators.
#[derive(Debug)]
pub struct Node {
    config: NodeConfig,
    state: DriveState,
    faults: Faults,
    actuators: Vec<ActuatorSim>,
    params: NodeParams,
    /// The last host heartbeat: when, and the host's protocol version.
    host: Option<(Instant, ProtocolVersion)>,
    next_heartbeat: Option<Instant>,
    next_feedback: Option<Instant>,
    /// `Emergency` events waiting for a poll (serial).
    pending: VecDeque<Emergency>,
    outbox: Vec<Packet>,
    noise: Option<Normal<f64>>,
    force_noise: Option<Normal<f64>>,
    rng: ChaCha8Rng,
}

impl Node {
    /// Powers a node on at `now`: Disabled, nothing homed; on CAN its boot-up heartbeat is in
    /// the outbox.
    pub fn power_on(mut config: NodeConfig, now: Instant) -> Self {
        config.actuators.truncate(MAX_ACTUATORS);
        let noise = Normal::new(0.0, config.noise_mm).ok().filter(|_| config.noise_mm > 0.0);
        let force_noise =
            Normal::new(0.0, config.force_noise_n).ok().filter(|_| config.force_noise_n > 0.0);
        let rng = ChaCha8Rng::seed_from_u64(config.seed);
        let mut node = Self {
            actuators: Vec::new(),
            state: DriveState::Disabled,
            faults: Faults::empty(),
            params: NodeParams::default(),
            host: None,
            next_heartbeat: None,
            next_feedback: None,
            pending: VecDeque::new(),
            outbox: Vec::new(),
            noise,
            force_noise,
            rng,
            config,
        };
        let capability = node.speed_and_accel_capability();
        node.actuators = node
            .config
            .actuators
            .iter()
            .map(|&a| ActuatorSim::power_on(a, capability, now))
            .collect();
        node.boot(now);
        node
    }

    /// Reboots the node's controller at `now` (a power glitch, a firmware reset): the state,
    /// homes, parameters and staged targets are lost; the panels stay where they are.
    pub fn reboot(&mut self, now: Instant) {
        let capability = self.speed_and_accel_capability();
        self.actuators = self.actuators.iter().map(|a| a.reboot(capability, now)).collect();
        self.state = DriveState::Disabled;
        self.faults = Faults::empty();
        self.params = NodeParams::default();
        self.host = None;
        self.pending.clear();
        self.outbox.clear();
        self.boot(now);
    }

    fn boot(&mut self, now: Instant) {
        self.next_heartbeat = params::next_after(now, self.params.heartbeat_ms, now);
        self.next_feedback = params::next_after(now, self.params.feedback_ms, now);
        if self.speaks_unasked() {
            self.send_heartbeat(now);
        }
    }

    /// Its address.
    pub fn id(&self) -> NodeId {
        self.config.id
    }

    /// Its drive state.
    pub fn state(&self) -> DriveState {
        self.state
    }

    /// Its latched faults.
    pub fn faults(&self) -> Faults {
        self.faults
    }

    /// The truth about its actuators at `now`, by index.
    pub fn actuator_states(&self, now: Instant) -> Vec<ActuatorState> {
        self.actuators
            .iter()
            .map(|a| ActuatorState {
                position_mm: a.position(now),
                velocity_mm_s: a.velocity(now),
                homed: a.homed,
                moving: a.is_moving(now),
                staged: a.staged,
                stalled: a.is_jammed(),
                encoder_fault: a.encoder_broken,
                load_n: a.load_n,
                force_limit_n: f64::from(a.params.force_limit) / HUNDREDTHS_PER_N,
            })
            .collect()
    }

    /// The packets it has sent since the last call, in order.
    pub fn take_outgoing(&mut self) -> Vec<Packet> {
        std::mem::take(&mut self.outbox)
    }

    /// Injects a physical fault into one of its actuators at `now` (ignored for an actuator
    /// it lacks).
    pub fn inject(&mut self, now: Instant, actuator: Actuator, fault: ActuatorFault) {
        self.advance(now);
        if let Some(a) = self.actuators.get_mut(actuator.index()) {
            a.inject(now, fault);
        }
    }

    /// Puts an external load on one of its actuators, N, positive inwards (what a garment on
    /// the form presses on the panel; ignored for an actuator it lacks). A node of protocol
    /// 1.1 measures it, and stalls an actuator whose load is over its limit at its next tick.
    /// The node's time does not move: only its own runner advances it (see `robot::runners`
    /// on stalls).
    pub fn apply_load(&mut self, actuator: Actuator, load_n: f64) {
        if let Some(a) = self.actuators.get_mut(actuator.index()) {
            a.load_n = load_n;
        }
    }

    /// Repairs one of its actuators at `now` (see [`ActuatorFault`]): no longer jammed, its
    /// encoder working; latched faults stay until a FaultReset.
    pub fn repair(&mut self, now: Instant, actuator: Actuator) {
        self.advance(now);
        if let Some(a) = self.actuators.get_mut(actuator.index()) {
            a.repair(now);
        }
    }

    /// The simulator itself stood still for `lost` (its process was descheduled): a real
    /// node never does, so its watchdog does not count that time against the host.
    pub fn excuse(&mut self, lost: Duration) {
        if let Some((at, version)) = self.host {
            self.host = Some((at + lost, version));
        }
    }

    /// Lets time pass up to `now`: motion, homing, monitoring, the watchdog and cyclic
    /// frames.
    pub fn tick(&mut self, now: Instant) {
        self.advance(now);
    }

    /// Takes a packet from the bus at `now`.
    pub fn receive(&mut self, now: Instant, packet: &Packet) {
        let for_us = match packet.address {
            Address::Broadcast => true,
            Address::Node(id) => id == self.config.id,
        };
        let from_host = packet.message.code().direction() == Direction::HostToNode;
        if !(for_us && from_host) {
            return;
        }
        self.advance(now);
        let to = packet.address;
        match packet.message {
            Message::EmergencyStop => self.raise(now, EmergencyCode::EMERGENCY_STOP, None, 0),
            Message::Sync(sync) => self.sync(now, sync.duration_ms),
            Message::Targets(four) => self.stage(four.half.first(), &four.positions),
            Message::AllTargets(all) => self.stage(0, &all.positions),
            Message::HostHeartbeat(heartbeat) => {
                self.host = Some((now, heartbeat.protocol));
                if to != Address::Broadcast {
                    self.answer_poll(now);
                }
            }
            Message::Control(command) => {
                let status = self.control(now, command);
                self.ack(to, Code::Control, status);
            }
            Message::Home(set) => {
                let status = self.home(now, set);
                self.ack(to, Code::Home, status);
            }
            Message::MotionLimits(limits) => {
                let status = self.motion_limits(limits);
                self.ack(to, Code::MotionLimits, status);
            }
            Message::IdentifyRequest => {
                self.answer(to, Message::Identity(self.identity()));
                self.answer(to, Message::Capabilities(self.capabilities()));
            }
            Message::ParamRead(read) => match self.read_param(read) {
                Ok(value) => self.answer(
                    to,
                    Message::ParamValue(Param {
                        param: read.param,
                        actuator: read.actuator,
                        value,
                    }),
                ),
                Err(status) => self.ack(to, Code::ParamRead, status),
            },
            Message::ParamWrite(write) => {
                let status = match self.write_param(now, write) {
                    Ok(()) => AckStatus::Ok,
                    Err(status) => status,
                };
                self.ack(to, Code::ParamWrite, status);
            }
            // Node → host messages were filtered out above.
            Message::Emergency(_)
            | Message::Feedback(_)
            | Message::AllFeedback(_)
            | Message::Heartbeat(_)
            | Message::Identity(_)
            | Message::Capabilities(_)
            | Message::ParamValue(_)
            | Message::Ack(_)
            | Message::Force(_)
            | Message::AllForce(_) => {}
        }
    }

    /// Whether this node sends frames nobody asked for (CAN: yes; serial: never).
    fn speaks_unasked(&self) -> bool {
        self.config.link != Link::Serial
    }

    fn send(&mut self, message: Message) {
        self.outbox.push(Packet::node(self.config.id, message));
    }

    /// Sends an answer to a request sent `to` this node or to all (not to broadcasts on
    /// serial).
    fn answer(&mut self, to: Address, message: Message) {
        if to != Address::Broadcast || self.speaks_unasked() {
            self.send(message);
        }
    }

    fn ack(&mut self, to: Address, request: Code, status: AckStatus) {
        self.answer(to, Message::Ack(Ack { request, status }));
    }

    fn heartbeat(&self, now: Instant) -> Heartbeat {
        let set = |f: &dyn Fn(&ActuatorSim) -> bool| -> ActuatorSet {
            self.channels().filter(|(_, a)| f(a)).map(|(i, _)| i).collect()
        };
        Heartbeat {
            state: self.state,
            faults: self.faults,
            homed: set(&|a| a.homed),
            moving: set(&|a| a.is_moving(now)),
            staged: set(&|a| a.staged.is_some()),
        }
    }

    /// The actuators with their protocol index.
    fn channels(&self) -> impl Iterator<Item = (Actuator, &ActuatorSim)> {
        Actuator::all().zip(&self.actuators)
    }

    fn send_heartbeat(&mut self, now: Instant) {
        let heartbeat = self.heartbeat(now);
        self.send(Message::Heartbeat(heartbeat));
    }

    /// The feedback messages of this link: the halves on classic CAN (only the lower one for
    /// at most four actuators), `AllFeedback` otherwise.
    fn send_feedback(&mut self, now: Instant) {
        let mut all = Positions8::default();
        for (slot, actuator) in all.positions.iter_mut().zip(&self.actuators) {
            let noise = clipped(&self.noise, self.config.noise_mm, &mut self.rng);
            *slot = actuator.measured(now, noise);
        }
        let halves = self.actuators.len() > MAX_ACTUATORS / 2;
        match self.config.link {
            Link::ClassicCan => {
                self.send(Message::Feedback(all.half(Half::Lower)));
                if halves {
                    self.send(Message::Feedback(all.half(Half::Upper)));
                }
            }
            Link::CanFd | Link::Serial => self.send(Message::AllFeedback(all)),
        }
        if self.reports_force() {
            self.send_forces();
        }
    }

    /// Whether it sends forces: it measures them (1.1) and its host announced a version
    /// that reads them.
    fn reports_force(&self) -> bool {
        self.config.protocol.has_force() && self.host.is_some_and(|(_, host)| host.has_force())
    }

    /// The forces of this link's feedback: the halves on classic CAN, `AllForce` otherwise.
    fn send_forces(&mut self) {
        let mut all = Forces8::default();
        for (slot, actuator) in all.forces.iter_mut().zip(&self.actuators) {
            let noise = clipped(&self.force_noise, self.config.force_noise_n, &mut self.rng);
            *slot = actuator.measured_force(noise);
        }
        let halves = self.actuators.len() > MAX_ACTUATORS / 2;
        match self.config.link {
            Link::ClassicCan => {
                self.send(Message::Force(all.half(Half::Lower)));
                if halves {
                    self.send(Message::Force(all.half(Half::Upper)));
                }
            }
            Link::CanFd | Link::Serial => self.send(Message::AllForce(all)),
        }
    }

    /// Answers a poll: heartbeat, positions, and on serial the pending events.
    fn answer_poll(&mut self, now: Instant) {
        self.send_heartbeat(now);
        self.send_feedback(now);
        while let Some(event) = self.pending.pop_front() {
            self.send(Message::Emergency(event));
        }
    }

    /// Reports an event: at once on CAN, with the next poll's answer on serial.
    fn report(&mut self, code: EmergencyCode, actuator: Option<Actuator>, detail: i32) {
        let event = Emergency { code, actuator, detail };
        if self.speaks_unasked() {
            self.send(Message::Emergency(event));
        } else {
            if self.pending.len() == PENDING_EMERGENCIES {
                self.pending.pop_front();
            }
            self.pending.push_back(event);
        }
    }

    fn set_state(&mut self, now: Instant, state: DriveState) {
        if state != self.state {
            self.state = state;
            if self.speaks_unasked() {
                self.send_heartbeat(now);
            }
        }
    }

    /// Latches a fault: report it, stop everything at the acceleration limits, power off.
    fn raise(
        &mut self,
        now: Instant,
        code: EmergencyCode,
        actuator: Option<Actuator>,
        detail: i32,
    ) {
        self.faults |= code.fault();
        self.report(code, actuator, detail);
        self.stop_all(now);
        self.set_state(now, DriveState::Fault);
    }

    /// Brakes every actuator at its acceleration limit and drops staged targets.
    fn stop_all(&mut self, now: Instant) {
        for actuator in &mut self.actuators {
            actuator.brake(now);
            actuator.staged = None;
        }
    }

    /// Advances monitoring to `now` (see [`Node::tick`]).
    fn advance(&mut self, now: Instant) {
        let powered = matches!(self.state, DriveState::Enabled | DriveState::Homing);
        let mut faults = Vec::new();
        for (index, actuator) in Actuator::all().zip(self.actuators.iter_mut()) {
            actuator.update_homing(now);
            if actuator.encoder_broken && !actuator.encoder_reported {
                actuator.encoder_reported = true;
                actuator.lose_position(now);
                faults.push((index, (ENCODER_GLITCH_MM * HUNDREDTHS_PER_MM) as i32));
            } else if powered
                && actuator.following_error(now) > f64::from(actuator.params.following_error_limit)
            {
                let error = actuator.following_error(now).round() as i32;
                actuator.lose_position(now);
                faults.push((index, error));
            }
        }
        for (index, error) in faults {
            self.raise(now, EmergencyCode::FOLLOWING_ERROR, Some(index), error);
        }
        if powered && self.config.protocol.has_force() {
            self.check_forces(now);
        }
        if self.state == DriveState::Homing && !self.actuators.iter().any(ActuatorSim::is_homing) {
            self.set_state(now, DriveState::Enabled);
        }
        if matches!(self.state, DriveState::Enabled | DriveState::Homing) {
            let silence = self.host.map(|(at, _)| now.saturating_duration_since(at));
            let timeout = Duration::from_millis(u64::from(self.params.watchdog_ms));
            if silence.is_none_or(|s| s > timeout) {
                let ms = silence.map_or(i32::MAX, |s| s.as_millis().min(i32::MAX as u128) as i32);
                self.raise(now, EmergencyCode::HOST_TIMEOUT, None, ms);
            }
        }
        if self.speaks_unasked() {
            if let Some(due) = self.next_heartbeat.filter(|&due| now >= due) {
                self.next_heartbeat = params::next_after(due, self.params.heartbeat_ms, now);
                self.send_heartbeat(now);
            }
            if let Some(due) = self.next_feedback.filter(|&due| now >= due) {
                self.next_feedback = params::next_after(due, self.params.feedback_ms, now);
                self.send_feedback(now);
            }
        }
    }

    /// Stalls every actuator whose load is over its force limit and latches `OVER_FORCE`
    /// (the others stop at their acceleration limits, as for any fault).
    fn check_forces(&mut self, now: Instant) {
        let mut over = Vec::new();
        for (index, actuator) in Actuator::all().zip(self.actuators.iter_mut()) {
            if actuator.over_force() {
                actuator.stall(now);
                let force = actuator.measured_force(0.0).unwrap_or(Force::MAX);
                over.push((index, i32::from(force.hundredths_n())));
            }
        }
        for (index, force) in over {
            self.raise(now, EmergencyCode::OVER_FORCE, Some(index), force);
        }
    }

    /// Stages the targets of the slots from `first` (`None` keeps a slot as it is).
    fn stage(&mut self, first: usize, targets: &[Option<Position>]) {
        for (index, target) in (first..).zip(targets) {
            let (Some(target), Some(actuator)) = (*target, self.actuators.get_mut(index)) else {
                continue;
            };
            let refusal = if !actuator.homed {
                Some((EmergencyCode::NOT_HOMED, 0))
            } else if !(actuator.params.soft_min..=actuator.params.soft_max)
                .contains(&target.hundredths_mm())
            {
                Some((EmergencyCode::TARGET_OUT_OF_RANGE, i32::from(target.hundredths_mm())))
            } else {
                None
            };
            actuator.staged = if refusal.is_some() { None } else { Some(target) };
            if let Some((code, detail)) = refusal {
                self.report(code, Actuator::new(index as u8), detail);
            }
        }
    }

    /// SYNC: in Enabled start every staged move; in any other state drop them.
    fn sync(&mut self, now: Instant, duration_ms: u16) {
        let enabled = self.state == DriveState::Enabled;
        let mut late = Vec::new();
        for (index, actuator) in Actuator::all().zip(self.actuators.iter_mut()) {
            let Some(target) = actuator.staged.take() else { continue };
            if enabled
                && actuator.homed
                && let Some(required_ms) = actuator.start_move(now, target, duration_ms)
            {
                late.push((index, required_ms));
            }
        }
        for (index, required_ms) in late {
            let detail = i32::try_from(required_ms).unwrap_or(i32::MAX);
            self.report(EmergencyCode::DURATION_TOO_SHORT, Some(index), detail);
        }
    }

    /// `Control`: the drive state machine.
    fn control(&mut self, now: Instant, command: DriveCommand) -> AckStatus {
        use DriveState::{Disabled, Enabled, Fault, Homing};
        match (command, self.state) {
            (DriveCommand::Enable, Disabled) => {
                let timeout = Duration::from_millis(u64::from(self.params.watchdog_ms));
                match self.host {
                    Some((at, _)) if now.saturating_duration_since(at) > timeout => {
                        AckStatus::InvalidState
                    }
                    None => AckStatus::InvalidState,
                    Some((_, host)) if host.major != self.config.protocol.major => {
                        AckStatus::IncompatibleVersion
                    }
                    Some(_) => {
                        self.set_state(now, Enabled);
                        AckStatus::Ok
                    }
                }
            }
            (DriveCommand::Enable, Enabled | Homing) => AckStatus::Ok,
            (DriveCommand::Enable | DriveCommand::Disable, Fault) => AckStatus::InvalidState,
            (DriveCommand::Disable, Enabled | Homing) => {
                self.stop_all(now);
                self.set_state(now, Disabled);
                AckStatus::Ok
            }
            (DriveCommand::Disable, Disabled) => AckStatus::Ok,
            (DriveCommand::Halt, Enabled | Homing) => {
                self.stop_all(now);
                self.set_state(now, Enabled);
                AckStatus::Ok
            }
            (DriveCommand::Halt, Disabled | Fault) => AckStatus::Ok,
            (DriveCommand::FaultReset, Fault) => self.fault_reset(now),
            (DriveCommand::FaultReset, Disabled | Enabled | Homing) => AckStatus::Ok,
        }
    }

    /// `FaultReset` in Fault: clear the flags whose cause is gone.
    fn fault_reset(&mut self, now: Instant) -> AckStatus {
        let mut remaining = Faults::empty();
        let timeout = Duration::from_millis(u64::from(self.params.watchdog_ms));
        let host_alive =
            self.host.is_some_and(|(at, _)| now.saturating_duration_since(at) <= timeout);
        if self.faults.contains(Faults::HOST_TIMEOUT) && !host_alive {
            remaining |= Faults::HOST_TIMEOUT;
        }
        if self.faults.contains(Faults::FOLLOWING_ERROR)
            && self.actuators.iter().any(|a| a.encoder_broken)
        {
            remaining |= Faults::FOLLOWING_ERROR;
        }
        self.faults = remaining;
        if remaining.is_empty() {
            self.report(EmergencyCode::NO_ERROR, None, 0);
            self.set_state(now, DriveState::Disabled);
            AckStatus::Ok
        } else {
            AckStatus::InvalidState
        }
    }

    /// `Home`: start homing the set (Enabled or Homing only).
    fn home(&mut self, now: Instant, set: ActuatorSet) -> AckStatus {
        if !matches!(self.state, DriveState::Enabled | DriveState::Homing) {
            return AckStatus::InvalidState;
        }
        if set.iter().any(|a| a.index() >= self.actuators.len()) {
            return AckStatus::InvalidArgument;
        }
        for index in set.iter() {
            if let Some(actuator) = self.actuators.get_mut(index.index())
                && !actuator.is_homing()
            {
                actuator.start_homing(now);
            }
        }
        if self.actuators.iter().any(ActuatorSim::is_homing) {
            self.set_state(now, DriveState::Homing);
        }
        AckStatus::Ok
    }

    /// `MotionLimits`: new speed and acceleration limits for the set (bits of actuators the
    /// node lacks are ignored), from the next SYNC.
    fn motion_limits(&mut self, limits: MotionLimits) -> AckStatus {
        let (speed, accel) = self.speed_and_accel_capability();
        let (max_speed, max_accel) =
            (limits.max_speed.hundredths_mm_s(), limits.max_accel.tenths_mm_s2());
        if !(1..=speed).contains(&max_speed) || !(1..=accel).contains(&max_accel) {
            return AckStatus::InvalidArgument;
        }
        for index in limits.actuators.iter() {
            if let Some(actuator) = self.actuators.get_mut(index.index()) {
                actuator.params.max_speed = max_speed;
                actuator.params.max_accel = max_accel;
            }
        }
        AckStatus::Ok
    }

    fn identity(&self) -> Identity {
        Identity {
            protocol: self.config.protocol,
            firmware: self.config.firmware,
            actuator_count: self.actuators.len() as u8,
        }
    }

    /// The weakest of its actuators.
    fn capabilities(&self) -> Capabilities {
        let stroke = self.actuators.iter().map(|a| a.config.stroke).min();
        let (speed, accel) = self.speed_and_accel_capability();
        Capabilities {
            stroke: stroke.unwrap_or(Position::ZERO),
            max_speed: Speed::from_hundredths_mm_s(speed),
            max_accel: Accel::from_tenths_mm_s2(accel),
        }
    }

    fn speed_and_accel_capability(&self) -> (u16, u16) {
        let actuators = &self.config.actuators;
        let speed = actuators.iter().map(|a| a.max_speed).min().unwrap_or(0);
        let accel = actuators.iter().map(|a| a.max_accel).min().unwrap_or(0);
        (speed, accel)
    }
}
