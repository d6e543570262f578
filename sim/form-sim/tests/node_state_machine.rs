//! The simulated node alone, without a bus: the README's state machine table, answers,
//! staging, parameters, homing and actuator faults. Time is explicit (`Instant`s).

use firmware_protocol::drive::{AckStatus, DriveCommand, DriveState, EmergencyCode, Faults};
use firmware_protocol::message::{
    Ack, Emergency, Half, HostHeartbeat, MotionLimits, Param, ParamRead, Positions4, Positions8,
    Sync,
};
use firmware_protocol::param::ParamId;
use firmware_protocol::update::shortest_duration_ms;
use firmware_protocol::version::{FirmwareVersion, PROTOCOL_1_0};
use firmware_protocol::{
    Accel, Actuator, ActuatorSet, Code, Link, Message, NodeId, PROTOCOL_VERSION, Packet, Position,
    ProtocolVersion, Speed,
};
use form_sim::node::{ActuatorConfig, ActuatorFault, Node, NodeConfig};
use tokio::time::{Duration, Instant};

const ID: NodeId = NodeId::MIN;

fn config(link: Link, actuators: usize) -> NodeConfig {
    let actuator = ActuatorConfig {
        stroke: Position::new(5000).unwrap(),
        max_speed: 1000,
        max_accel: 500,
        start_mm: 1.0,
        rated_force: RATED_FORCE,
    };
    NodeConfig {
        id: ID,
        link,
        actuators: vec![actuator; actuators],
        firmware: FirmwareVersion { major: 2, minor: 3, patch: 4 },
        noise_mm: 0.0,
        force_noise_n: 0.0,
        protocol: PROTOCOL_VERSION,
        seed: 1,
    }
}

/// The actuators' rated force in these tests, 0.01 N (80 N).
const RATED_FORCE: u16 = 8000;

fn actuator(index: u8) -> Actuator {
    Actuator::new(index).unwrap()
}

fn to_node(message: Message) -> Packet {
    Packet::node(ID, message)
}

/// A heartbeat of a host of protocol `major`.0.
fn heartbeat(major: u8) -> Message {
    Message::HostHeartbeat(HostHeartbeat { protocol: ProtocolVersion { major, minor: 0 } })
}

/// A heartbeat of a host of this crate's protocol version (1.1: it reads forces).
fn heartbeat_1_1() -> Message {
    Message::HostHeartbeat(HostHeartbeat { protocol: PROTOCOL_VERSION })
}

fn ack(request: Code, status: AckStatus) -> Packet {
    Packet::node(ID, Message::Ack(Ack { request, status }))
}

/// A node with a clock: receives, ticks and collects what it sends.
struct Bench {
    node: Node,
    now: Instant,
    /// When the watchdog was last fed by `run`.
    fed: Instant,
}

impl Bench {
    fn new(link: Link, actuators: usize) -> Self {
        let now = Instant::now();
        Self { node: Node::power_on(config(link, actuators), now), now, fed: now }
    }

    fn send(&mut self, packet: Packet) -> Vec<Packet> {
        self.node.receive(self.now, &packet);
        self.node.take_outgoing()
    }

    /// Lets `ms` milliseconds pass in 1 ms ticks, feeding the watchdog every 100 ms.
    fn run(&mut self, ms: u64) -> Vec<Packet> {
        let mut sent = Vec::new();
        for _ in 0..ms {
            self.now += Duration::from_millis(1);
            if self.now - self.fed >= Duration::from_millis(100) {
                self.fed = self.now;
                self.node.receive(self.now, &Packet::broadcast(heartbeat(1)));
            }
            self.node.tick(self.now);
            sent.extend(self.node.take_outgoing());
        }
        sent
    }

    /// Enabled, every actuator homed.
    fn ready(link: Link, actuators: usize) -> Self {
        let mut bench = Self::new(link, actuators);
        bench.node.take_outgoing();
        bench.send(to_node(heartbeat(1)));
        bench.send(to_node(Message::Control(DriveCommand::Enable)));
        bench.send(to_node(Message::Home(ActuatorSet::from_bits(((1u16 << actuators) - 1) as u8))));
        bench.run(1000);
        assert_eq!(bench.node.state(), DriveState::Enabled);
        assert!(bench.node.actuator_states(bench.now).iter().all(|a| a.homed));
        bench
    }
}

fn events(sent: &[Packet]) -> Vec<Emergency> {
    sent.iter()
        .filter_map(|p| match p.message {
            Message::Emergency(e) => Some(e),
            _ => None,
        })
        .collect()
}

#[test]
fn a_can_node_announces_itself_at_power_on_and_a_serial_node_stays_quiet() {
    let mut can = Bench::new(Link::ClassicCan, 8);
    let boot = can.node.take_outgoing();
    assert!(matches!(boot[..], [Packet { message: Message::Heartbeat(h), .. }]
        if h.state == DriveState::Disabled && h.homed.is_empty()));
    assert!(Bench::new(Link::Serial, 8).node.take_outgoing().is_empty());
    // CAN: heartbeats every 100 ms and both feedback halves every 20 ms.
    let sent = can.run(200);
    let count = |code| sent.iter().filter(|p| p.message.code() == code).count();
    assert_eq!((count(Code::Heartbeat), count(Code::FeedbackLower)), (2, 10));
    assert_eq!(count(Code::FeedbackUpper), 10);
    // A node with four actuators sends only the lower half.
    let sent = Bench::new(Link::ClassicCan, 4).run(100);
    assert!(!sent.iter().any(|p| p.message.code() == Code::FeedbackUpper));
}

#[test]
fn enable_needs_a_recent_heartbeat_of_the_same_major_version() {
    let mut bench = Bench::new(Link::ClassicCan, 8);
    bench.node.take_outgoing();
    let enable = to_node(Message::Control(DriveCommand::Enable));
    assert_eq!(bench.send(enable), [ack(Code::Control, AckStatus::InvalidState)]);
    bench.send(Packet::broadcast(heartbeat(2)));
    assert_eq!(bench.send(enable), [ack(Code::Control, AckStatus::IncompatibleVersion)]);
    bench.send(Packet::broadcast(heartbeat(1)));
    bench.now += Duration::from_millis(301);
    let late = bench.send(enable);
    assert_eq!(late.last(), Some(&ack(Code::Control, AckStatus::InvalidState)));
    bench.send(Packet::broadcast(heartbeat(1)));
    let sent = bench.send(enable);
    // The state change is announced at once, then the Ack.
    assert!(matches!(sent[0].message, Message::Heartbeat(h) if h.state == DriveState::Enabled));
    assert_eq!(sent[1], ack(Code::Control, AckStatus::Ok));
    // Asking again for the same state is Ok and changes nothing.
    assert_eq!(bench.send(enable), [ack(Code::Control, AckStatus::Ok)]);
}

#[test]
fn the_state_machine_answers_as_the_readme_table_says() {
    use AckStatus::{InvalidArgument, InvalidState, Ok};
    let mut bench = Bench::new(Link::Serial, 4);
    let control = |c| to_node(Message::Control(c));
    let home = |bits| to_node(Message::Home(ActuatorSet::from_bits(bits)));
    bench.send(to_node(heartbeat(1)));
    assert_eq!(bench.send(home(1)), [ack(Code::Home, InvalidState)]);
    assert_eq!(bench.send(control(DriveCommand::Disable)), [ack(Code::Control, Ok)]);
    assert_eq!(bench.send(control(DriveCommand::FaultReset)), [ack(Code::Control, Ok)]);
    assert_eq!(bench.send(control(DriveCommand::Enable)), [ack(Code::Control, Ok)]);
    assert_eq!(bench.send(home(0b1_0000)), [ack(Code::Home, InvalidArgument)], "no actuator 4");
    assert_eq!(bench.send(home(0b11)), [ack(Code::Home, Ok)]);
    assert_eq!(bench.node.state(), DriveState::Homing);
    assert_eq!(bench.send(home(0b100)), [ack(Code::Home, Ok)], "adds to the homing set");
    assert_eq!(bench.send(control(DriveCommand::Halt)), [ack(Code::Control, Ok)]);
    assert_eq!(bench.node.state(), DriveState::Enabled);
    assert!(bench.node.actuator_states(bench.now).iter().all(|a| !a.homed));
    bench.send(Packet::broadcast(Message::EmergencyStop));
    assert_eq!(bench.node.state(), DriveState::Fault);
    assert_eq!(bench.send(control(DriveCommand::Enable)), [ack(Code::Control, InvalidState)]);
    assert_eq!(bench.send(home(1)), [ack(Code::Home, InvalidState)]);
    let sent = bench.send(control(DriveCommand::FaultReset));
    assert_eq!(sent, [ack(Code::Control, Ok)]);
    assert_eq!((bench.node.state(), bench.node.faults()), (DriveState::Disabled, Faults::empty()));
    // On serial the events wait for the poll: e-stop, then NoError.
    let poll = bench.send(to_node(heartbeat(1)));
    let codes: Vec<_> = events(&poll).iter().map(|e| e.code).collect();
    assert_eq!(codes, [EmergencyCode::EMERGENCY_STOP, EmergencyCode::NO_ERROR]);
    assert!(matches!(
        poll[..2],
        [
            Packet { message: Message::Heartbeat(_), .. },
            Packet { message: Message::AllFeedback(_), .. },
        ]
    ));
}

#[test]
fn on_serial_broadcasts_are_obeyed_but_never_answered() {
    let mut bench = Bench::new(Link::Serial, 8);
    assert!(bench.send(Packet::broadcast(Message::IdentifyRequest)).is_empty());
    bench.send(Packet::broadcast(heartbeat(1)));
    assert!(bench.send(Packet::broadcast(Message::Control(DriveCommand::Enable))).is_empty());
    assert_eq!(bench.node.state(), DriveState::Enabled);
    let identity = bench.send(to_node(Message::IdentifyRequest));
    let [
        Packet { message: Message::Identity(id), .. },
        Packet { message: Message::Capabilities(c), .. },
    ] = identity[..]
    else {
        panic!("{identity:?}")
    };
    assert_eq!((id.protocol, id.actuator_count, id.firmware.patch), (PROTOCOL_VERSION, 8, 4));
    let limits = (c.max_speed.hundredths_mm_s(), c.max_accel.tenths_mm_s2());
    assert_eq!((c.stroke.hundredths_mm(), limits), (5000, (1000, 500)));
    // Other nodes' packets and node → host messages are ignored.
    assert!(bench.send(Packet::node(NodeId::new(2).unwrap(), Message::IdentifyRequest)).is_empty());
    assert!(
        bench
            .send(to_node(Message::Ack(Ack { request: Code::Home, status: AckStatus::Ok })))
            .is_empty()
    );
}

#[test]
fn targets_are_staged_only_for_homed_actuators_within_their_limits() {
    let mut bench = Bench::new(Link::ClassicCan, 8);
    bench.node.take_outgoing();
    let four = |positions| to_node(Message::Targets(Positions4 { half: Half::Lower, positions }));
    let sent = bench.send(four([Position::new(100), None, None, None]));
    assert_eq!(
        events(&sent),
        [Emergency { code: EmergencyCode::NOT_HOMED, actuator: Some(actuator(0)), detail: 0 }]
    );

    let mut bench = Bench::ready(Link::ClassicCan, 8);
    let sent = bench.send(four([Position::new(1000), Position::new(5001), None, None]));
    assert_eq!(
        events(&sent),
        [Emergency {
            code: EmergencyCode::TARGET_OUT_OF_RANGE,
            actuator: Some(actuator(1)),
            detail: 5001
        }]
    );
    let staged: Vec<_> = bench.node.actuator_states(bench.now).iter().map(|a| a.staged).collect();
    assert_eq!(staged[..2], [Position::new(1000), None]);
    // A soft limit refuses too, and clears what was staged before.
    let write = Param { param: ParamId::SOFT_LIMIT_MAX, actuator: Some(actuator(0)), value: 800 };
    assert_eq!(
        bench.send(to_node(Message::ParamWrite(write))),
        [ack(Code::ParamWrite, AckStatus::Ok)]
    );
    let sent = bench.send(four([Position::new(900), None, None, None]));
    assert_eq!(events(&sent)[0].code, EmergencyCode::TARGET_OUT_OF_RANGE);
    assert_eq!(bench.node.actuator_states(bench.now)[0].staged, None);
    // SYNC moves nothing that was refused.
    bench.send(Packet::broadcast(Message::Sync(Sync { duration_ms: 0 })));
    bench.run(3000);
    assert!(bench.node.actuator_states(bench.now).iter().all(|a| a.position_mm == 0.0));
}

#[test]
fn a_sync_too_short_moves_at_the_limits_and_reports_the_shortest_duration() {
    let mut bench = Bench::ready(Link::ClassicCan, 8);
    let mut all = Positions8::default();
    all.positions[0] = Position::new(4000);
    all.positions[1] = Position::new(500);
    bench.send(to_node(Message::Targets(all.half(Half::Lower))));
    let start = bench.now;
    let sent = bench.send(Packet::broadcast(Message::Sync(Sync { duration_ms: 1000 })));
    let limits = (Speed::from_hundredths_mm_s(1000), Accel::from_tenths_mm_s2(500));
    let shortest = shortest_duration_ms(4000, limits.0, limits.1).unwrap();
    assert_eq!(
        events(&sent),
        [Emergency {
            code: EmergencyCode::DURATION_TOO_SHORT,
            actuator: Some(actuator(0)),
            detail: shortest as i32
        }]
    );
    // The other one makes it in the SYNC's time; the late one as fast as it can.
    bench.run(1000);
    let states = bench.node.actuator_states(bench.now);
    assert!((states[1].position_mm - 5.0).abs() < 1e-9 && !states[1].moving);
    assert!(states[0].moving);
    bench.run(u64::from(shortest) - 1000);
    assert_eq!(bench.now - start, Duration::from_millis(u64::from(shortest)));
    assert!((bench.node.actuator_states(bench.now)[0].position_mm - 40.0).abs() < 1e-9);
}

#[test]
fn a_sync_outside_enabled_drops_the_staged_targets() {
    let mut bench = Bench::ready(Link::ClassicCan, 8);
    bench.send(to_node(Message::AllTargets(Positions8 { positions: [Position::new(2000); 8] })));
    bench.send(to_node(Message::Control(DriveCommand::Disable)));
    bench.send(to_node(Message::AllTargets(Positions8 { positions: [Position::new(2000); 8] })));
    bench.send(Packet::broadcast(Message::Sync(Sync { duration_ms: 0 })));
    let states = bench.node.actuator_states(bench.now);
    assert!(states.iter().all(|a| a.staged.is_none() && !a.moving));
}

#[test]
fn parameters_have_the_readme_scopes_and_ranges() {
    use AckStatus::{InvalidArgument, Ok, ReadOnlyParameter, UnknownParameter};
    let mut bench = Bench::new(Link::Serial, 4);
    let read = |param, actuator| to_node(Message::ParamRead(ParamRead { param, actuator }));
    let write =
        |param, actuator, value| to_node(Message::ParamWrite(Param { param, actuator, value }));
    let value = |param, actuator, value| {
        Packet::node(ID, Message::ParamValue(Param { param, actuator, value }))
    };
    assert_eq!(
        bench.send(read(ParamId::WATCHDOG_TIMEOUT, None)),
        [value(ParamId::WATCHDOG_TIMEOUT, None, 300)]
    );
    assert_eq!(
        bench.send(read(ParamId::STROKE, Some(actuator(3)))),
        [value(ParamId::STROKE, Some(actuator(3)), 5000)]
    );
    assert_eq!(bench.send(read(ParamId::STROKE, None)), [ack(Code::ParamRead, InvalidArgument)]);
    assert_eq!(
        bench.send(read(ParamId::STROKE, Some(actuator(4)))),
        [ack(Code::ParamRead, InvalidArgument)]
    );
    assert_eq!(bench.send(read(ParamId(0x8001), None)), [ack(Code::ParamRead, UnknownParameter)]);
    let cases = [
        (write(ParamId::WATCHDOG_TIMEOUT, None, 5), InvalidArgument),
        (write(ParamId::WATCHDOG_TIMEOUT, Some(actuator(0)), 500), InvalidArgument),
        (write(ParamId::WATCHDOG_TIMEOUT, None, 500), Ok),
        (write(ParamId::STROKE, Some(actuator(0)), 1), ReadOnlyParameter),
        (write(ParamId::MAX_SPEED, None, 1001), InvalidArgument),
        (write(ParamId::MAX_SPEED, None, 700), Ok),
        (write(ParamId::SOFT_LIMIT_MIN, Some(actuator(1)), 5001), InvalidArgument),
        (write(ParamId(0x0109), None, 1), UnknownParameter),
    ];
    for (request, status) in cases {
        assert_eq!(bench.send(request), [ack(Code::ParamWrite, status)], "{request:?}");
    }
    assert_eq!(
        bench.send(read(ParamId::MAX_SPEED, Some(actuator(3)))),
        [value(ParamId::MAX_SPEED, Some(actuator(3)), 700)]
    );
    let limits = |max_speed, max_accel| {
        to_node(Message::MotionLimits(MotionLimits {
            actuators: ActuatorSet::ALL,
            max_speed: Speed::from_hundredths_mm_s(max_speed),
            max_accel: Accel::from_tenths_mm_s2(max_accel),
        }))
    };
    assert_eq!(bench.send(limits(1000, 501)), [ack(Code::MotionLimits, InvalidArgument)]);
    assert_eq!(bench.send(limits(0, 100)), [ack(Code::MotionLimits, InvalidArgument)]);
    assert_eq!(bench.send(limits(400, 100)), [ack(Code::MotionLimits, Ok)]);
    assert_eq!(
        bench.send(read(ParamId::MAX_ACCEL, Some(actuator(2)))),
        [value(ParamId::MAX_ACCEL, Some(actuator(2)), 100)]
    );
}

#[test]
fn homing_finds_the_switch_and_comes_back_to_zero_within_the_limits() {
    let mut bench = Bench::new(Link::ClassicCan, 2);
    bench.send(to_node(heartbeat(1)));
    bench.send(to_node(Message::Control(DriveCommand::Enable)));
    // ALL would name actuators 2..=7, which this node lacks.
    let all = bench.send(to_node(Message::Home(ActuatorSet::ALL)));
    assert_eq!(all.last(), Some(&ack(Code::Home, AckStatus::InvalidArgument)));
    bench.send(to_node(Message::Home(ActuatorSet::from_bits(0b11))));
    let mut lowest = f64::MAX;
    let mut done_at = None;
    for ms in 1..=1000 {
        bench.run(1);
        let state = &bench.node.actuator_states(bench.now)[0];
        lowest = lowest.min(state.position_mm);
        assert!(state.velocity_mm_s.abs() <= 5.0 + 1e-9, "homes at HomingSpeed (5 mm/s)");
        if state.homed && done_at.is_none() {
            done_at = Some(ms);
        }
    }
    // 1 mm towards the switch (0.1 s ramp to 5 mm/s, 0.15 s cruise), 0.1 s braking past it
    // (0.25 mm at 50 mm/s²), 0.14 s back to 0.
    let done_at = done_at.expect("never homed");
    assert!((480..500).contains(&done_at), "homed after {done_at} ms");
    assert!(lowest < 0.0 && lowest > -0.3, "overtravel {lowest}");
    let state = &bench.node.actuator_states(bench.now)[0];
    assert_eq!((state.position_mm, bench.node.state()), (0.0, DriveState::Enabled));
}

#[test]
fn a_jammed_actuator_raises_a_following_error_once_it_is_asked_to_move() {
    let mut bench = Bench::ready(Link::ClassicCan, 8);
    bench.node.inject(bench.now, actuator(2), ActuatorFault::Stall);
    assert!(bench.run(100).iter().all(|p| !matches!(p.message, Message::Emergency(_))));
    bench.send(to_node(Message::AllTargets(Positions8 { positions: [Position::new(3000); 8] })));
    bench.send(Packet::broadcast(Message::Sync(Sync { duration_ms: 0 })));
    let sent = bench.run(1000);
    let event = events(&sent)[0];
    assert_eq!((event.code, event.actuator), (EmergencyCode::FOLLOWING_ERROR, Some(actuator(2))));
    assert!(event.detail > 100, "the error exceeded the 1 mm limit: {}", event.detail);
    assert_eq!(
        (bench.node.state(), bench.node.faults()),
        (DriveState::Fault, Faults::FOLLOWING_ERROR)
    );
    let states = bench.node.actuator_states(bench.now);
    assert!(!states[2].homed && states[2].position_mm == 0.0);
    assert!(states.iter().all(|a| !a.moving), "every actuator stopped");
    // The jam cannot be seen at rest: the flag resets, the home stays lost.
    let reset = bench.send(to_node(Message::Control(DriveCommand::FaultReset)));
    assert_eq!(reset.last(), Some(&ack(Code::Control, AckStatus::Ok)));
}

#[test]
fn a_broken_encoder_faults_at_once_and_cannot_be_reset() {
    let mut bench = Bench::ready(Link::ClassicCan, 8);
    bench.node.inject(bench.now, actuator(5), ActuatorFault::Encoder);
    let sent = bench.run(2);
    assert_eq!(events(&sent)[0].code, EmergencyCode::FOLLOWING_ERROR);
    let reset = bench.send(to_node(Message::Control(DriveCommand::FaultReset)));
    assert_eq!(reset, [ack(Code::Control, AckStatus::InvalidState)]);
    assert_eq!(bench.node.state(), DriveState::Fault);
    // Its feedback is unknown from then on.
    let poll = bench.send(to_node(heartbeat(1)));
    let Some(Message::Feedback(upper)) =
        poll.iter().map(|p| p.message).find(|m| m.code() == Code::FeedbackUpper)
    else {
        panic!("{poll:?}")
    };
    assert_eq!(upper.positions[1], None);
}

#[test]
fn a_reboot_forgets_everything_but_where_the_panels_are() {
    let mut bench = Bench::ready(Link::ClassicCan, 8);
    bench.send(to_node(Message::AllTargets(Positions8 { positions: [Position::new(2000); 8] })));
    bench.send(Packet::broadcast(Message::Sync(Sync { duration_ms: 0 })));
    bench.run(3000);
    bench.node.reboot(bench.now);
    let boot = bench.node.take_outgoing();
    assert!(matches!(boot[..], [Packet { message: Message::Heartbeat(h), .. }]
        if h.state == DriveState::Disabled && h.homed.is_empty()));
    let states = bench.node.actuator_states(bench.now);
    assert!(states.iter().all(|a| a.position_mm == 20.0 && !a.homed));
}

/// Forces (protocol 1.1) go with the feedback only to a host that reads them: on serial the
/// poll answer is heartbeat, positions, forces; on classic CAN both force halves follow the
/// feedback halves every 20 ms; a 1.0 host (and any host of a 1.0 node) sees none.
#[test]
fn forces_go_with_the_feedback_to_a_host_that_reads_them() {
    let codes = |sent: &[Packet]| sent.iter().map(|p| p.message.code()).collect::<Vec<_>>();
    let mut serial = Bench::new(Link::Serial, 8);
    serial.node.apply_load(actuator(3), 12.5);
    assert_eq!(codes(&serial.send(to_node(heartbeat(1)))), [Code::Heartbeat, Code::AllFeedback]);
    let answer = serial.send(to_node(heartbeat_1_1()));
    assert_eq!(codes(&answer), [Code::Heartbeat, Code::AllFeedback, Code::AllForce]);
    let Message::AllForce(forces) = answer[2].message else { unreachable!() };
    assert_eq!(forces.forces[3].map(|f| f.n()), Some(12.5));
    assert_eq!(forces.forces[0].map(|f| f.n()), Some(0.0));

    let mut can = Bench::new(Link::ClassicCan, 8);
    can.send(Packet::broadcast(heartbeat_1_1()));
    can.fed = can.now;
    let sent = can.run(99);
    let count = |code| sent.iter().filter(|p| p.message.code() == code).count();
    assert_eq!((count(Code::ForceLower), count(Code::ForceUpper)), (4, 4), "{:?}", codes(&sent));
    // `run` feeds a 1.0 heartbeat at 100 ms (after the feedback due then): from then on no
    // forces.
    can.run(1);
    let later = can.run(100);
    assert!(!later.iter().any(|p| matches!(p.message, Message::Force(_))));

    let mut old = Node::power_on(
        NodeConfig { protocol: PROTOCOL_1_0, ..config(Link::Serial, 8) },
        serial.now,
    );
    old.receive(serial.now, &to_node(heartbeat_1_1()));
    assert_eq!(codes(&old.take_outgoing()), [Code::Heartbeat, Code::AllFeedback]);
}

/// `ForceLimit` defaults to the rated force and takes 1..=rated; `RatedForce` is read-only;
/// a 1.0 node knows neither.
#[test]
fn the_force_limit_is_a_1_1_parameter_up_to_the_rated_force() {
    let mut bench = Bench::new(Link::Serial, 2);
    let read = |bench: &mut Bench, param| {
        bench.send(to_node(Message::ParamRead(ParamRead { param, actuator: Some(actuator(1)) })))
    };
    let write = |bench: &mut Bench, value| {
        bench.send(to_node(Message::ParamWrite(Param {
            param: ParamId::FORCE_LIMIT,
            actuator: None,
            value,
        })))
    };
    let value = |param, value| {
        vec![to_node_answer(Message::ParamValue(Param {
            param,
            actuator: Some(actuator(1)),
            value,
        }))]
    };
    assert_eq!(read(&mut bench, ParamId::FORCE_LIMIT), value(ParamId::FORCE_LIMIT, 8000));
    assert_eq!(read(&mut bench, ParamId::RATED_FORCE), value(ParamId::RATED_FORCE, 8000));
    assert_eq!(write(&mut bench, 2500), [ack(Code::ParamWrite, AckStatus::Ok)]);
    assert_eq!(read(&mut bench, ParamId::FORCE_LIMIT), value(ParamId::FORCE_LIMIT, 2500));
    for bad in [0, 8001, -5] {
        assert_eq!(write(&mut bench, bad), [ack(Code::ParamWrite, AckStatus::InvalidArgument)]);
    }
    let rated = bench.send(to_node(Message::ParamWrite(Param {
        param: ParamId::RATED_FORCE,
        actuator: None,
        value: 100,
    })));
    assert_eq!(rated, [ack(Code::ParamWrite, AckStatus::ReadOnlyParameter)]);

    let mut old = Bench {
        node: Node::power_on(
            NodeConfig { protocol: PROTOCOL_1_0, ..config(Link::Serial, 2) },
            bench.now,
        ),
        ..bench
    };
    assert_eq!(write(&mut old, 2500), [ack(Code::ParamWrite, AckStatus::UnknownParameter)]);
}

fn to_node_answer(message: Message) -> Packet {
    Packet::node(ID, message)
}

/// A panel pushing into a load over its force limit stops where it is at once, and the node
/// latches `OVER_FORCE` naming it with the force; FaultReset clears it (the push stopped). A
/// 1.0 node, which measures nothing, moves on.
#[test]
fn an_actuator_over_its_force_limit_stalls_and_latches_over_force() {
    let mut bench = Bench::ready(Link::ClassicCan, 8);
    bench.send(to_node(Message::AllTargets(Positions8 { positions: [Position::new(4000); 8] })));
    bench.send(Packet::broadcast(Message::Sync(Sync { duration_ms: 0 })));
    bench.run(500);
    let before = bench.node.actuator_states(bench.now)[6];
    assert!(before.moving && before.position_mm > 2.0 && before.position_mm < 38.0, "{before:?}");
    bench.node.apply_load(actuator(6), 80.5);
    let sent = bench.run(1);
    let event = events(&sent)[0];
    assert_eq!(
        (event.code, event.actuator, event.detail),
        (EmergencyCode::OVER_FORCE, Some(actuator(6)), 8050)
    );
    assert_eq!((bench.node.state(), bench.node.faults()), (DriveState::Fault, Faults::OVER_FORCE));
    let stalled = bench.node.actuator_states(bench.now)[6];
    assert!(
        !stalled.moving && (stalled.position_mm - before.position_mm).abs() < 0.02,
        "{stalled:?}"
    );
    assert!(stalled.homed, "a stall keeps the home: the encoder is right");
    bench.run(1000);
    assert_eq!(bench.node.actuator_states(bench.now)[6].position_mm, stalled.position_mm);
    let reset = bench.send(to_node(Message::Control(DriveCommand::FaultReset)));
    assert_eq!(reset.last(), Some(&ack(Code::Control, AckStatus::Ok)));

    let mut old = Bench {
        node: Node::power_on(
            NodeConfig { protocol: PROTOCOL_1_0, ..config(Link::ClassicCan, 8) },
            bench.now,
        ),
        ..bench
    };
    old.send(to_node(heartbeat(1)));
    old.send(to_node(Message::Control(DriveCommand::Enable)));
    old.node.apply_load(actuator(6), 200.0);
    old.run(50);
    assert_eq!(old.node.state(), DriveState::Enabled);
}
