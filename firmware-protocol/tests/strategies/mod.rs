//! Proptest strategies for every valid packet, shared by the integration tests.

use std::ops::RangeInclusive;

use firmware_protocol::drive::{AckStatus, DriveCommand, DriveState, EmergencyCode, Faults};
use firmware_protocol::message::{
    Ack, Addressing, Capabilities, Emergency, Forces4, Forces8, Half, Heartbeat, HostHeartbeat,
    Identity, MotionLimits, Param, ParamRead, Positions4, Positions8, Sync,
};
use firmware_protocol::param::ParamId;
use firmware_protocol::version::FirmwareVersion;
use firmware_protocol::{
    Accel, Actuator, ActuatorSet, Address, Code, Force, Message, NodeId, Packet, Position,
    ProtocolVersion, Speed,
};
use proptest::prelude::*;
use proptest::sample::select;

fn position() -> impl Strategy<Value = Option<Position>> {
    // Often "none", often the ends of the range, otherwise anything.
    prop_oneof![
        1 => Just(None),
        1 => select(vec![Position::ZERO, Position::MAX]).prop_map(Some),
        4 => (0..=Position::MAX.hundredths_mm()).prop_map(Position::new),
    ]
}

fn force() -> impl Strategy<Value = Option<Force>> {
    // Often "not measured", often the ends of the range and no load, otherwise anything but
    // the reserved i16::MIN (which is "not measured" on the wire).
    prop_oneof![
        1 => Just(None),
        1 => select(vec![Force::MAX, Force::new(-i16::MAX).unwrap(), Force::ZERO]).prop_map(Some),
        4 => (-i16::MAX..=i16::MAX).prop_map(Force::new),
    ]
}

fn actuator() -> impl Strategy<Value = Option<Actuator>> {
    prop_oneof![Just(None), (0..8u8).prop_map(Actuator::new)]
}

fn set() -> impl Strategy<Value = ActuatorSet> {
    any::<u8>().prop_map(ActuatorSet::from_bits)
}

fn protocol() -> impl Strategy<Value = ProtocolVersion> {
    any::<(u8, u8)>().prop_map(|(major, minor)| ProtocolVersion { major, minor })
}

fn param() -> impl Strategy<Value = Param> {
    (any::<u16>(), actuator(), any::<i32>()).prop_map(|(id, actuator, value)| Param {
        param: ParamId(id),
        actuator,
        value,
    })
}

fn half() -> impl Strategy<Value = Half> {
    prop_oneof![Just(Half::Lower), Just(Half::Upper)]
}

fn four() -> impl Strategy<Value = Positions4> {
    (half(), [position(), position(), position(), position()])
        .prop_map(|(half, positions)| Positions4 { half, positions })
}

fn eight() -> impl Strategy<Value = Positions8> {
    proptest::array::uniform8(position()).prop_map(|positions| Positions8 { positions })
}

fn forces4() -> impl Strategy<Value = Forces4> {
    (half(), [force(), force(), force(), force()])
        .prop_map(|(half, forces)| Forces4 { half, forces })
}

fn forces8() -> impl Strategy<Value = Forces8> {
    proptest::array::uniform8(force()).prop_map(|forces| Forces8 { forces })
}

/// Every valid message, each kind about equally often.
fn message() -> impl Strategy<Value = Message> {
    prop_oneof![
        Just(Message::EmergencyStop),
        any::<u16>().prop_map(|duration_ms| Message::Sync(Sync { duration_ms })),
        (any::<u16>(), actuator(), any::<i32>()).prop_map(|(code, actuator, detail)| {
            Message::Emergency(Emergency { code: EmergencyCode(code), actuator, detail })
        }),
        four().prop_map(Message::Targets),
        eight().prop_map(Message::AllTargets),
        four().prop_map(Message::Feedback),
        eight().prop_map(Message::AllFeedback),
        protocol().prop_map(|protocol| Message::HostHeartbeat(HostHeartbeat { protocol })),
        (select(DriveState::ALL.to_vec()), any::<u16>(), set(), set(), set()).prop_map(
            |(state, faults, homed, moving, staged)| Message::Heartbeat(Heartbeat {
                state,
                faults: Faults::from_bits_retain(faults),
                homed,
                moving,
                staged,
            })
        ),
        select(DriveCommand::ALL.to_vec()).prop_map(Message::Control),
        set().prop_map(Message::Home),
        (set(), any::<u16>(), any::<u16>()).prop_map(|(actuators, max_speed, max_accel)| {
            Message::MotionLimits(MotionLimits {
                actuators,
                max_speed: Speed::from_hundredths_mm_s(max_speed),
                max_accel: Accel::from_tenths_mm_s2(max_accel),
            })
        }),
        Just(Message::IdentifyRequest),
        (protocol(), any::<(u8, u8, u8)>(), 1..=8u8).prop_map(
            |(protocol, (major, minor, patch), actuator_count)| Message::Identity(Identity {
                protocol,
                firmware: FirmwareVersion { major, minor, patch },
                actuator_count,
            })
        ),
        (position(), any::<u16>(), any::<u16>()).prop_filter_map(
            "a stroke is a position",
            |(stroke, max_speed, max_accel)| Some(Message::Capabilities(Capabilities {
                stroke: stroke?,
                max_speed: Speed::from_hundredths_mm_s(max_speed),
                max_accel: Accel::from_tenths_mm_s2(max_accel),
            }))
        ),
        (any::<u16>(), actuator()).prop_map(|(id, actuator)| {
            Message::ParamRead(ParamRead { param: ParamId(id), actuator })
        }),
        param().prop_map(Message::ParamWrite),
        param().prop_map(Message::ParamValue),
        (select(Code::ALL.to_vec()), select(AckStatus::ALL.to_vec()))
            .prop_map(|(request, status)| Message::Ack(Ack { request, status })),
        forces4().prop_map(Message::Force),
        forces8().prop_map(Message::AllForce),
    ]
}

/// Every valid packet with a node address in `nodes` (or broadcast, where allowed).
pub fn packet(nodes: RangeInclusive<u8>) -> impl Strategy<Value = Packet> {
    let node =
        nodes.prop_filter_map("node ids are 1..=63", |id| NodeId::new(id).map(Address::Node));
    (message(), node, any::<bool>()).prop_map(|(message, node, broadcast)| {
        let address = match message.code().addressing() {
            Addressing::Broadcast => Address::Broadcast,
            Addressing::Node => node,
            Addressing::NodeOrBroadcast if broadcast => Address::Broadcast,
            Addressing::NodeOrBroadcast => node,
        };
        Packet { address, message }
    })
}
