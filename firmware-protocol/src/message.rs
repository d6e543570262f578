//! The messages, their function codes, and who may send them to whom.
//!
//! A [`Packet`] is a [`Message`] plus an [`Address`]: the node it goes to (host → node) or
//! comes from (node → host), or every node (broadcast). Both mappings carry exactly these
//! packets: [`can`](crate::can) puts the function [`Code`] and the address into the CAN
//! identifier, [`serial`](crate::serial) into a frame header. Every message is one frame.
//!
//! Host → node: `EmergencyStop`, `Sync`, `Targets`, `AllTargets`, `HostHeartbeat`,
//! `Control`, `Home`, `MotionLimits`, `IdentifyRequest`, `ParamRead`, `ParamWrite`.
//! Node → host: `Emergency`, `Feedback`, `AllFeedback`, `Heartbeat`, `Identity`,
//! `Capabilities`, `ParamValue`, `Ack`, and since 1.1 `Force` and `AllForce`. The byte
//! layouts are in [`payload`](crate::payload).

use crate::Error;
use crate::actuator::{Accel, Actuator, ActuatorSet, Force, MAX_ACTUATORS, Position, Speed};
use crate::drive::{AckStatus, DriveCommand, DriveState, EmergencyCode, Faults};
use crate::param::ParamId;
use crate::version::{FirmwareVersion, ProtocolVersion};

/// A node's id on the bus, 1..=63 (0 is the broadcast address).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct NodeId(u8);

impl NodeId {
    /// The lowest node id.
    pub const MIN: Self = Self(1);
    /// The highest node id (6 bits).
    pub const MAX: Self = Self(63);

    /// The node id `id`, if in 1..=63.
    pub const fn new(id: u8) -> Option<Self> {
        if id >= Self::MIN.0 && id <= Self::MAX.0 { Some(Self(id)) } else { None }
    }

    /// The id, 1..=63.
    pub const fn get(self) -> u8 {
        self.0
    }
}

/// Where a packet goes to (host → node) or comes from (node → host).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Address {
    /// Every node (wire value 0).
    Broadcast,
    /// One node (wire value 1..=63).
    Node(NodeId),
}

impl Address {
    /// The wire value: 0 for broadcast, else the node id.
    pub const fn to_u8(self) -> u8 {
        match self {
            Self::Broadcast => 0,
            Self::Node(node) => node.0,
        }
    }

    /// The address with this wire value, if in 0..=63.
    pub const fn from_u8(raw: u8) -> Option<Self> {
        match raw {
            0 => Some(Self::Broadcast),
            _ => match NodeId::new(raw) {
                Some(node) => Some(Self::Node(node)),
                None => None,
            },
        }
    }
}

/// Which way a message travels.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Direction {
    /// Sent by the host.
    HostToNode,
    /// Sent by a node.
    NodeToHost,
}

/// Which addresses a message may carry.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Addressing {
    /// Broadcast only (e-stop, SYNC, host heartbeat).
    Broadcast,
    /// One node: the receiver (host → node) or the sender (node → host).
    Node,
    /// One node, or all of them. On CAN every node answers a broadcast request; on a serial
    /// line nobody does (their answers would collide).
    NodeOrBroadcast,
}

macro_rules! codes {
    ($($(#[$doc:meta])* $name:ident = $value:literal, $dir:ident, $addr:ident, $len:literal,
       [$($answer:ident),*];)*) => {
        /// The function code of a message (5 bits): its CAN priority class and its identity
        /// on every mapping. Codes 24..=30 are free for minor versions; 31 is never used (it
        /// would make CAN ids 0x7F0..=0x7FF, which old controllers reject).
        #[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
        #[repr(u8)]
        pub enum Code {
            $($(#[$doc])* $name = $value,)*
        }

        impl Code {
            /// Every code, in priority (= numeric) order.
            pub const ALL: [Code; [$($value),*].len()] = [$(Code::$name),*];

            /// The code with this value.
            pub const fn from_u8(raw: u8) -> Option<Code> {
                match raw {
                    $($value => Some(Code::$name),)*
                    _ => None,
                }
            }

            /// Who sends messages with this code.
            pub const fn direction(self) -> Direction {
                match self {
                    $(Code::$name => Direction::$dir,)*
                }
            }

            /// The addresses messages with this code may carry.
            pub const fn addressing(self) -> Addressing {
                match self {
                    $(Code::$name => Addressing::$addr,)*
                }
            }

            /// The payload length in bytes (the CAN data length).
            pub const fn payload_len(self) -> usize {
                match self {
                    $(Code::$name => $len,)*
                }
            }

            /// The name, as in the DBC file and the README.
            pub const fn name(self) -> &'static str {
                match self {
                    $(Code::$name => stringify!($name),)*
                }
            }

            /// What a node sends back to a request with this code, in the order it sends
            /// them (empty: nothing is answered). A request may also be refused with an
            /// `Ack` naming its code ([`Message::answers`]).
            pub const fn answers(self) -> &'static [Code] {
                match self {
                    $(Code::$name => &[$(Code::$answer),*],)*
                }
            }
        }
    };
}

codes! {
    /// Stop everything now (broadcast, highest priority).
    EmergencyStop = 0, HostToNode, Broadcast, 0, [];
    /// Start all staged moves, lasting a common duration.
    Sync = 1, HostToNode, Broadcast, 2, [];
    /// A fault or warning event.
    Emergency = 2, NodeToHost, Node, 7, [];
    /// Staged targets of actuators 0..=3.
    TargetsLower = 3, HostToNode, Node, 8, [];
    /// Staged targets of actuators 4..=7.
    TargetsUpper = 4, HostToNode, Node, 8, [];
    /// Staged targets of all eight actuators (CAN FD / serial).
    AllTargets = 5, HostToNode, Node, 16, [];
    /// Actual positions of actuators 0..=3.
    FeedbackLower = 6, NodeToHost, Node, 8, [];
    /// Actual positions of actuators 4..=7.
    FeedbackUpper = 7, NodeToHost, Node, 8, [];
    /// Actual positions of all eight actuators (CAN FD / serial).
    AllFeedback = 8, NodeToHost, Node, 16, [];
    /// The host is alive (feeds the node watchdogs; addressed, it polls one node, which
    /// answers with its heartbeat and positions, then, to a host of 1.1, its forces: not
    /// listed among the answers, since a 1.0 node does not send them).
    HostHeartbeat = 9, HostToNode, NodeOrBroadcast, 2, [Heartbeat, AllFeedback];
    /// A node's state, faults and actuator status.
    Heartbeat = 10, NodeToHost, Node, 6, [];
    /// A drive state machine command.
    Control = 11, HostToNode, NodeOrBroadcast, 1, [Ack];
    /// Home some actuators.
    Home = 12, HostToNode, NodeOrBroadcast, 1, [Ack];
    /// Speed and acceleration limits for some actuators.
    MotionLimits = 13, HostToNode, NodeOrBroadcast, 5, [Ack];
    /// Ask for `Identity` and `Capabilities`.
    IdentifyRequest = 14, HostToNode, NodeOrBroadcast, 0, [Identity, Capabilities];
    /// Protocol and firmware versions, actuator count.
    Identity = 15, NodeToHost, Node, 6, [];
    /// Stroke, speed and acceleration limits of the node's actuators.
    Capabilities = 16, NodeToHost, Node, 6, [];
    /// Read a parameter (refused with an `Ack` naming it).
    ParamRead = 17, HostToNode, Node, 3, [ParamValue];
    /// Write a parameter.
    ParamWrite = 18, HostToNode, NodeOrBroadcast, 7, [Ack];
    /// A parameter's value (answer to `ParamRead`).
    ParamValue = 19, NodeToHost, Node, 7, [];
    /// The outcome of a request.
    Ack = 20, NodeToHost, Node, 2, [];
    /// Measured forces of actuators 0..=3 (protocol 1.1).
    ForceLower = 21, NodeToHost, Node, 8, [];
    /// Measured forces of actuators 4..=7 (protocol 1.1).
    ForceUpper = 22, NodeToHost, Node, 8, [];
    /// Measured forces of all eight actuators (CAN FD / serial; protocol 1.1).
    AllForce = 23, NodeToHost, Node, 16, [];
}

impl Code {
    /// The protocol minor version (of major 1) that introduced this code: a host sends a
    /// node, and a node sends a host, only codes of the minor version they share.
    pub const fn since_minor(self) -> u8 {
        match self {
            Code::ForceLower | Code::ForceUpper | Code::AllForce => 1,
            _ => 0,
        }
    }
}

/// One half of a node's actuators.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Half {
    /// Actuators 0..=3.
    Lower,
    /// Actuators 4..=7.
    Upper,
}

impl Half {
    /// The index of the half's first actuator (0 or 4).
    pub const fn first(self) -> usize {
        match self {
            Self::Lower => 0,
            Self::Upper => MAX_ACTUATORS / 2,
        }
    }
}

/// Positions of four actuators, one half of a node (a classic CAN frame's worth).
/// `None` is "keep the staged target" in set-points, "unknown" in feedback.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Positions4 {
    /// Which four actuators.
    pub half: Half,
    /// Their positions, lowest index first.
    pub positions: [Option<Position>; 4],
}

/// Positions of all eight actuators of a node. `None` as in [`Positions4`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct Positions8 {
    /// Positions of actuators 0..=7.
    pub positions: [Option<Position>; MAX_ACTUATORS],
}

impl Positions8 {
    /// The four positions of one half.
    pub fn half(&self, half: Half) -> Positions4 {
        let mut positions = [None; 4];
        positions.copy_from_slice(&self.positions[half.first()..half.first() + 4]);
        Positions4 { half, positions }
    }

    /// Overwrites one half with `four`'s positions (to merge the two classic frames).
    pub fn set_half(&mut self, four: &Positions4) {
        let first = four.half.first();
        self.positions[first..first + 4].copy_from_slice(&four.positions);
    }
}

/// Measured forces of four actuators, one half of a node (a classic CAN frame's worth;
/// protocol 1.1). `None` is "not measured" (an actuator without a force sensor).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Forces4 {
    /// Which four actuators.
    pub half: Half,
    /// Their forces, lowest index first.
    pub forces: [Option<Force>; 4],
}

/// Measured forces of all eight actuators of a node (protocol 1.1). `None` as in
/// [`Forces4`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct Forces8 {
    /// Forces of actuators 0..=7.
    pub forces: [Option<Force>; MAX_ACTUATORS],
}

impl Forces8 {
    /// The four forces of one half.
    pub fn half(&self, half: Half) -> Forces4 {
        let mut forces = [None; 4];
        forces.copy_from_slice(&self.forces[half.first()..half.first() + 4]);
        Forces4 { half, forces }
    }

    /// Overwrites one half with `four`'s forces (to merge the two classic frames).
    pub fn set_half(&mut self, four: &Forces4) {
        let first = four.half.first();
        self.forces[first..first + 4].copy_from_slice(&four.forces);
    }
}

/// `Sync`: every node starts its staged moves now.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Sync {
    /// How long every move lasts (ms), so that all actuators arrive together; 0 = each
    /// actuator as fast as its limits allow.
    pub duration_ms: u16,
}

impl Sync {
    /// The longest move a SYNC can ask for, ms (`duration_ms` is a `u16` on the wire).
    pub const MAX_DURATION_MS: u16 = u16::MAX;
}

/// `Emergency`: a node reports a fault or a warning.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Emergency {
    /// What happened.
    pub code: EmergencyCode,
    /// Which actuator, or `None` for the node as a whole.
    pub actuator: Option<Actuator>,
    /// A code-specific value (see [`EmergencyCode`]).
    pub detail: i32,
}

/// `HostHeartbeat`: the host is alive.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct HostHeartbeat {
    /// The host's protocol version (nodes refuse `Enable` from another major version).
    pub protocol: ProtocolVersion,
}

/// `Heartbeat`: a node's state.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Heartbeat {
    /// Drive state.
    pub state: DriveState,
    /// Latched faults.
    pub faults: Faults,
    /// Actuators whose home is known.
    pub homed: ActuatorSet,
    /// Actuators moving (or homing) now.
    pub moving: ActuatorSet,
    /// Actuators with a staged target waiting for SYNC.
    pub staged: ActuatorSet,
}

/// `MotionLimits`: speed and acceleration limits for some actuators.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct MotionLimits {
    /// Which actuators.
    pub actuators: ActuatorSet,
    /// Speed limit.
    pub max_speed: Speed,
    /// Acceleration (and deceleration) limit.
    pub max_accel: Accel,
}

/// `Identity`: who a node is.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Identity {
    /// The protocol version the node speaks.
    pub protocol: ProtocolVersion,
    /// Its firmware version.
    pub firmware: FirmwareVersion,
    /// How many actuators it drives, 1..=8 (actuators 0..count).
    pub actuator_count: u8,
}

/// `Capabilities`: what a node's actuators can do (the weakest of them, if they differ;
/// per-actuator values are parameters).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Capabilities {
    /// Stroke: targets lie in 0..=stroke.
    pub stroke: Position,
    /// Highest speed.
    pub max_speed: Speed,
    /// Highest acceleration.
    pub max_accel: Accel,
}

/// `ParamRead`: ask for a parameter.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct ParamRead {
    /// Which parameter.
    pub param: ParamId,
    /// Which actuator, or `None` for a node parameter.
    pub actuator: Option<Actuator>,
}

/// `ParamWrite` and `ParamValue`: a parameter and its value.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Param {
    /// Which parameter.
    pub param: ParamId,
    /// Which actuator, or `None` for a node parameter (or all actuators, when writing).
    pub actuator: Option<Actuator>,
    /// The value, in the parameter's unit.
    pub value: i32,
}

/// `Ack`: the outcome of a request.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Ack {
    /// The function code of the request.
    pub request: Code,
    /// The outcome.
    pub status: AckStatus,
}

/// Every message of the protocol. Which requests are answered, and how, is in the README.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Message {
    /// Stop everything now; every node latches `EMERGENCY_STOP`. No answer.
    EmergencyStop,
    /// Start the staged moves. No answer.
    Sync(Sync),
    /// A node's fault or warning event.
    Emergency(Emergency),
    /// Stage targets for one half of a node's actuators. No answer.
    Targets(Positions4),
    /// Stage targets for all of a node's actuators (16 bytes: CAN FD or serial). No answer.
    AllTargets(Positions8),
    /// Actual positions of one half of a node's actuators.
    Feedback(Positions4),
    /// Actual positions of all of a node's actuators (16 bytes: CAN FD or serial).
    AllFeedback(Positions8),
    /// The host is alive; addressed to a node, also a poll (answered by `Heartbeat` and
    /// feedback).
    HostHeartbeat(HostHeartbeat),
    /// A node's state.
    Heartbeat(Heartbeat),
    /// Change the drive state. Answered by `Ack`.
    Control(DriveCommand),
    /// Home these actuators (node Enabled). Answered by `Ack` when homing starts.
    Home(ActuatorSet),
    /// Set limits. Answered by `Ack`.
    MotionLimits(MotionLimits),
    /// Ask who the node is. Answered by `Identity` then `Capabilities`.
    IdentifyRequest,
    /// Who a node is.
    Identity(Identity),
    /// What a node's actuators can do.
    Capabilities(Capabilities),
    /// Read a parameter (refused with an `Ack` naming it). Answered by `ParamValue`, or `Ack` on failure.
    ParamRead(ParamRead),
    /// Write a parameter. Answered by `Ack`.
    ParamWrite(Param),
    /// A parameter's value.
    ParamValue(Param),
    /// The outcome of a request.
    Ack(Ack),
    /// Measured forces of one half of a node's actuators (protocol 1.1).
    Force(Forces4),
    /// Measured forces of all of a node's actuators (16 bytes: CAN FD or serial; 1.1).
    AllForce(Forces8),
}

impl Message {
    /// The message's function code.
    pub const fn code(&self) -> Code {
        match self {
            Self::EmergencyStop => Code::EmergencyStop,
            Self::Sync(_) => Code::Sync,
            Self::Emergency(_) => Code::Emergency,
            Self::Targets(Positions4 { half: Half::Lower, .. }) => Code::TargetsLower,
            Self::Targets(Positions4 { half: Half::Upper, .. }) => Code::TargetsUpper,
            Self::AllTargets(_) => Code::AllTargets,
            Self::Feedback(Positions4 { half: Half::Lower, .. }) => Code::FeedbackLower,
            Self::Feedback(Positions4 { half: Half::Upper, .. }) => Code::FeedbackUpper,
            Self::AllFeedback(_) => Code::AllFeedback,
            Self::HostHeartbeat(_) => Code::HostHeartbeat,
            Self::Heartbeat(_) => Code::Heartbeat,
            Self::Control(_) => Code::Control,
            Self::Home(_) => Code::Home,
            Self::MotionLimits(_) => Code::MotionLimits,
            Self::IdentifyRequest => Code::IdentifyRequest,
            Self::Identity(_) => Code::Identity,
            Self::Capabilities(_) => Code::Capabilities,
            Self::ParamRead(_) => Code::ParamRead,
            Self::ParamWrite(_) => Code::ParamWrite,
            Self::ParamValue(_) => Code::ParamValue,
            Self::Ack(_) => Code::Ack,
            Self::Force(Forces4 { half: Half::Lower, .. }) => Code::ForceLower,
            Self::Force(Forces4 { half: Half::Upper, .. }) => Code::ForceUpper,
            Self::AllForce(_) => Code::AllForce,
        }
    }

    /// Whether this message (from a node) answers `request`: its code is one of the
    /// request's [`Code::answers`], or it is an `Ack` naming the request's code (an answer
    /// or a refusal).
    pub fn answers(&self, request: &Message) -> bool {
        let request = request.code();
        match self {
            Self::Ack(ack) => ack.request == request,
            reply => request.answers().contains(&reply.code()),
        }
    }
}

/// A message with its address: what travels in one CAN frame or one serial frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Packet {
    /// The receiving node (host → node), the sending node (node → host), or broadcast.
    pub address: Address,
    /// The message.
    pub message: Message,
}

impl Packet {
    /// A packet for (or from) one node.
    pub const fn node(node: NodeId, message: Message) -> Self {
        Self { address: Address::Node(node), message }
    }

    /// A packet for every node.
    pub const fn broadcast(message: Message) -> Self {
        Self { address: Address::Broadcast, message }
    }

    /// Checks the address against the message's [`Addressing`]; both mappings refuse to
    /// encode, and reject on decoding, a packet that fails this.
    pub const fn check_address(&self) -> Result<(), Error> {
        match (self.message.code().addressing(), self.address) {
            (Addressing::Broadcast, Address::Broadcast)
            | (Addressing::Node, Address::Node(_))
            | (Addressing::NodeOrBroadcast, _) => Ok(()),
            _ => Err(Error::InvalidAddress),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn requests_name_their_answers_and_answers_flow_back() {
        for code in Code::ALL {
            for &answer in code.answers() {
                assert_eq!(code.direction(), Direction::HostToNode, "{}", code.name());
                assert_eq!(answer.direction(), Direction::NodeToHost, "{}", answer.name());
            }
        }
        let enable = Message::Control(crate::drive::DriveCommand::Enable);
        let ok = |request| Message::Ack(Ack { request, status: crate::drive::AckStatus::Ok });
        assert!(ok(Code::Control).answers(&enable));
        assert!(!ok(Code::Home).answers(&enable));
        assert_eq!(Code::IdentifyRequest.answers(), [Code::Identity, Code::Capabilities]);
        assert!(!Message::EmergencyStop.answers(&Message::IdentifyRequest));
    }

    #[test]
    fn codes_are_dense_and_below_31() {
        for (i, code) in Code::ALL.iter().enumerate() {
            assert_eq!(*code as usize, i);
            assert_eq!(Code::from_u8(i as u8), Some(*code));
        }
        assert_eq!(Code::from_u8(Code::ALL.len() as u8), None);
        assert!(Code::ALL.len() < 31);
    }

    #[test]
    fn addresses_are_0_for_broadcast_and_1_to_63_for_nodes() {
        assert_eq!(Address::from_u8(0), Some(Address::Broadcast));
        assert_eq!(Address::from_u8(63).map(Address::to_u8), Some(63));
        assert_eq!(Address::from_u8(64), None);
        assert_eq!(NodeId::new(0), None);
    }

    #[test]
    fn halves_split_and_merge_eight_positions() {
        let mut all = Positions8::default();
        for (i, p) in all.positions.iter_mut().enumerate() {
            *p = Position::new(i as u16 * 100);
        }
        let mut merged = Positions8::default();
        merged.set_half(&all.half(Half::Upper));
        merged.set_half(&all.half(Half::Lower));
        assert_eq!(merged, all);
        assert_eq!(all.half(Half::Upper).positions[0], Position::new(400));
    }

    #[test]
    fn addressing_rules_are_enforced() {
        let node = NodeId::new(3).unwrap();
        assert!(Packet::broadcast(Message::EmergencyStop).check_address().is_ok());
        assert!(Packet::node(node, Message::EmergencyStop).check_address().is_err());
        let targets = Message::AllTargets(Positions8::default());
        assert!(Packet::broadcast(targets).check_address().is_err());
        assert!(Packet::node(node, targets).check_address().is_ok());
        assert!(Packet::broadcast(Message::IdentifyRequest).check_address().is_ok());
        assert!(Packet::node(node, Message::IdentifyRequest).check_address().is_ok());
    }
}
