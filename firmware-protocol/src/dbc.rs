//! The DBC description of the CAN mapping, for CAN tools (cantools, SavvyCAN, ...).
//!
//! [`MESSAGES`] describes the signals of every message: Intel (little-endian) bit numbering
//! as in the [`payload`](crate::payload) layouts, raw values as on the wire, and a factor of
//! 10^-decimals to physical units. [`write()`] renders it as a DBC file for nodes 1..=n (a DBC
//! lists CAN ids, and ours contain the node). The committed `firmware-protocol/dressform.dbc`
//! is `write` for the reference form's 9 nodes, and the tests keep it so: they regenerate it,
//! check with [`signal_values`] that the encoder puts every field where the DBC says, and
//! have cantools decode and encode frames with it.

use core::fmt::{self, Write};

use crate::actuator::{actuator_to_wire, force_to_wire, position_to_wire};
use crate::drive::{EmergencyCode, Faults};
use crate::message::{Addressing, Code, Direction, Message};
use crate::param::ParamId;
use crate::timing::{FEEDBACK_PERIOD_MS, HEARTBEAT_PERIOD_MS, HOST_HEARTBEAT_PERIOD_MS};
use crate::version::{PROTOCOL_VERSION, ProtocolVersion};
use crate::{Address, NodeId};

/// One signal of a message.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Signal {
    /// Name (unique within the message).
    pub name: &'static str,
    /// First bit, Intel numbering (byte × 8 + bit).
    pub start: u16,
    /// Length in bits.
    pub len: u8,
    /// Two's complement.
    pub signed: bool,
    /// Physical value = raw × 10^-decimals.
    pub decimals: u8,
    /// Physical unit.
    pub unit: &'static str,
    /// What it means.
    pub comment: &'static str,
    /// Names of special raw values.
    pub choices: &'static [(i64, &'static str)],
}

impl Signal {
    const fn new(name: &'static str, start: u16, len: u8, comment: &'static str) -> Self {
        Self { name, start, len, signed: false, decimals: 0, unit: "", comment, choices: &[] }
    }

    const fn unit(self, unit: &'static str, decimals: u8) -> Self {
        Self { unit, decimals, ..self }
    }

    const fn signed(self) -> Self {
        Self { signed: true, ..self }
    }

    const fn choices(self, choices: &'static [(i64, &'static str)]) -> Self {
        Self { choices, ..self }
    }

    /// The smallest and largest raw value.
    pub const fn raw_range(&self) -> (i64, i64) {
        if self.signed {
            (-(1 << (self.len - 1)), (1 << (self.len - 1)) - 1)
        } else {
            (0, (1 << self.len) - 1)
        }
    }
}

/// The DBC description of one message.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct MessageDef {
    /// Its function code (which fixes name, length, direction and addressing).
    pub code: Code,
    /// What it does.
    pub comment: &'static str,
    /// Cyclic period at the defaults, if cyclic on CAN.
    pub cycle_ms: Option<u16>,
    /// Its signals, in payload order.
    pub signals: &'static [Signal],
}

/// Most signals in one message.
pub const MAX_SIGNALS: usize = 16;

const KEEP: &[(i64, &str)] = &[(0xFFFF, "Keep")];
const UNKNOWN: &[(i64, &str)] = &[(0xFFFF, "Unknown")];
const NODE: &[(i64, &str)] = &[(0xFF, "Node")];
const NOT_MEASURED: &[(i64, &str)] = &[(i16::MIN as i64, "NotMeasured")];
const STATES: &[(i64, &str)] = &[(0, "Disabled"), (1, "Enabled"), (2, "Homing"), (3, "Fault")];
const COMMANDS: &[(i64, &str)] = &[(0, "Disable"), (1, "Enable"), (2, "FaultReset"), (3, "Halt")];
const STATUSES: &[(i64, &str)] = &[
    (0, "Ok"),
    (1, "UnsupportedMessage"),
    (2, "InvalidState"),
    (3, "InvalidArgument"),
    (4, "UnknownParameter"),
    (5, "ReadOnlyParameter"),
    (6, "IncompatibleVersion"),
];
const EMERGENCY_CODES: [(i64, &str); EmergencyCode::KNOWN.len()] = {
    let mut out = [(0, ""); EmergencyCode::KNOWN.len()];
    let mut i = 0;
    while i < out.len() {
        out[i] = (EmergencyCode::KNOWN[i].0.0 as i64, EmergencyCode::KNOWN[i].1);
        i += 1;
    }
    out
};
const PARAMS: [(i64, &str); ParamId::KNOWN.len()] = {
    let mut out = [(0, ""); ParamId::KNOWN.len()];
    let mut i = 0;
    while i < out.len() {
        out[i] = (ParamId::KNOWN[i].0.0 as i64, ParamId::KNOWN[i].1);
        i += 1;
    }
    out
};
const CODES: [(i64, &str); Code::ALL.len()] = {
    let mut out = [(0, ""); Code::ALL.len()];
    let mut i = 0;
    while i < out.len() {
        out[i] = (Code::ALL[i] as i64, Code::ALL[i].name());
        i += 1;
    }
    out
};

const fn target(name: &'static str, start: u16) -> Signal {
    Signal::new(name, start, 16, "Staged target; Keep = leave this actuator's staged target")
        .unit("mm", 2)
        .choices(KEEP)
}

const fn force(name: &'static str, start: u16) -> Signal {
    Signal::new(name, start, 16, "Measured force, positive inwards; NotMeasured = no sensor")
        .unit("N", 2)
        .signed()
        .choices(NOT_MEASURED)
}

const fn actual(name: &'static str, start: u16) -> Signal {
    Signal::new(name, start, 16, "Actual position; Unknown = not homed")
        .unit("mm", 2)
        .choices(UNKNOWN)
}

const ACTUATOR: Signal =
    Signal::new("Actuator", 16, 8, "Actuator index 0..7, or Node (0xFF)").choices(NODE);
const PARAM: Signal = Signal::new("Param", 0, 16, "Parameter id").choices(&PARAMS);
const VALUE: Signal = Signal::new("Value", 24, 32, "Value, in the parameter's unit").signed();
const SPEED: &str = "mm/s";
const ACCEL: &str = "mm/s^2";

/// The DBC description of every message, indexed by function code.
pub const MESSAGES: [MessageDef; Code::ALL.len()] = [
    MessageDef {
        code: Code::EmergencyStop,
        comment: "Stop everything now; every node latches the EMERGENCY_STOP fault",
        cycle_ms: None,
        signals: &[],
    },
    MessageDef {
        code: Code::Sync,
        comment: "Every node starts its staged moves now",
        cycle_ms: None,
        signals: &[Signal::new(
            "DurationMs",
            0,
            16,
            "Every staged move lasts this long; 0 = as fast as the limits allow",
        )
        .unit("ms", 0)],
    },
    MessageDef {
        code: Code::Emergency,
        comment: "A fault or warning event of a node",
        cycle_ms: None,
        signals: &[
            Signal::new("ErrorCode", 0, 16, "Emergency code (CiA 301 classes)")
                .choices(&EMERGENCY_CODES),
            ACTUATOR,
            Signal::new("Detail", 24, 32, "Code-specific value").signed(),
        ],
    },
    MessageDef {
        code: Code::TargetsLower,
        comment: "Staged targets of actuators 0..3, moved on SYNC",
        cycle_ms: None,
        signals: &[
            target("Target0", 0),
            target("Target1", 16),
            target("Target2", 32),
            target("Target3", 48),
        ],
    },
    MessageDef {
        code: Code::TargetsUpper,
        comment: "Staged targets of actuators 4..7, moved on SYNC",
        cycle_ms: None,
        signals: &[
            target("Target4", 0),
            target("Target5", 16),
            target("Target6", 32),
            target("Target7", 48),
        ],
    },
    MessageDef {
        code: Code::AllTargets,
        comment: "Staged targets of actuators 0..7, moved on SYNC (CAN FD)",
        cycle_ms: None,
        signals: &[
            target("Target0", 0),
            target("Target1", 16),
            target("Target2", 32),
            target("Target3", 48),
            target("Target4", 64),
            target("Target5", 80),
            target("Target6", 96),
            target("Target7", 112),
        ],
    },
    MessageDef {
        code: Code::FeedbackLower,
        comment: "Actual positions of actuators 0..3 (cyclic on classic CAN)",
        cycle_ms: Some(FEEDBACK_PERIOD_MS),
        signals: &[
            actual("Actual0", 0),
            actual("Actual1", 16),
            actual("Actual2", 32),
            actual("Actual3", 48),
        ],
    },
    MessageDef {
        code: Code::FeedbackUpper,
        comment: "Actual positions of actuators 4..7 (cyclic on classic CAN)",
        cycle_ms: Some(FEEDBACK_PERIOD_MS),
        signals: &[
            actual("Actual4", 0),
            actual("Actual5", 16),
            actual("Actual6", 32),
            actual("Actual7", 48),
        ],
    },
    MessageDef {
        code: Code::AllFeedback,
        comment: "Actual positions of actuators 0..7 (cyclic on CAN FD, instead of the halves)",
        cycle_ms: Some(FEEDBACK_PERIOD_MS),
        signals: &[
            actual("Actual0", 0),
            actual("Actual1", 16),
            actual("Actual2", 32),
            actual("Actual3", 48),
            actual("Actual4", 64),
            actual("Actual5", 80),
            actual("Actual6", 96),
            actual("Actual7", 112),
        ],
    },
    MessageDef {
        code: Code::HostHeartbeat,
        comment: "The host is alive (feeds the node watchdogs); addressed, it polls the node",
        cycle_ms: Some(HOST_HEARTBEAT_PERIOD_MS),
        signals: &[
            Signal::new("ProtocolMajor", 0, 8, "Host protocol major version"),
            Signal::new("ProtocolMinor", 8, 8, "Host protocol minor version"),
        ],
    },
    MessageDef {
        code: Code::Heartbeat,
        comment: "A node's drive state, faults and actuator status",
        cycle_ms: Some(HEARTBEAT_PERIOD_MS),
        signals: &[
            Signal::new("State", 0, 8, "Drive state").choices(STATES),
            Signal::new("FaultEmergencyStop", 8, 1, "EmergencyStop received"),
            Signal::new("FaultHostTimeout", 9, 1, "Host heartbeat lost"),
            Signal::new("FaultOvercurrent", 10, 1, "Motor current over limit"),
            Signal::new("FaultFollowingError", 11, 1, "Following error (stall)"),
            Signal::new("FaultOvertemperature", 12, 1, "Over temperature"),
            Signal::new("FaultUndervoltage", 13, 1, "Supply under voltage"),
            Signal::new("FaultOvervoltage", 14, 1, "Supply over voltage"),
            Signal::new("FaultLimitSwitch", 15, 1, "End switch hit outside homing"),
            Signal::new("FaultHomingFailed", 16, 1, "Homing failed"),
            Signal::new("FaultInternal", 17, 1, "Firmware error"),
            Signal::new("FaultOverForce", 18, 1, "Force over ForceLimit, actuator stalled (1.1)"),
            Signal::new("FaultReserved", 19, 5, "Fault bits 11..15, reserved (0)"),
            Signal::new("Homed", 24, 8, "Actuators homed (bit i = actuator i)"),
            Signal::new("Moving", 32, 8, "Actuators moving (bit i = actuator i)"),
            Signal::new("Staged", 40, 8, "Actuators with a staged target (bit i = actuator i)"),
        ],
    },
    MessageDef {
        code: Code::Control,
        comment: "Drive state machine command; answered by Ack",
        cycle_ms: None,
        signals: &[Signal::new("Command", 0, 8, "Command").choices(COMMANDS)],
    },
    MessageDef {
        code: Code::Home,
        comment: "Home these actuators; answered by Ack",
        cycle_ms: None,
        signals: &[Signal::new("Actuators", 0, 8, "Actuators to home (bit i = actuator i)")],
    },
    MessageDef {
        code: Code::MotionLimits,
        comment: "Speed and acceleration limits; answered by Ack",
        cycle_ms: None,
        signals: &[
            Signal::new("Actuators", 0, 8, "Actuators concerned (bit i = actuator i)"),
            Signal::new("MaxSpeed", 8, 16, "Speed limit").unit(SPEED, 2),
            Signal::new("MaxAccel", 24, 16, "Acceleration limit").unit(ACCEL, 1),
        ],
    },
    MessageDef {
        code: Code::IdentifyRequest,
        comment: "Ask for Identity and Capabilities",
        cycle_ms: None,
        signals: &[],
    },
    MessageDef {
        code: Code::Identity,
        comment: "Protocol and firmware versions and actuator count of a node",
        cycle_ms: None,
        signals: &[
            Signal::new("ProtocolMajor", 0, 8, "Node protocol major version"),
            Signal::new("ProtocolMinor", 8, 8, "Node protocol minor version"),
            Signal::new("FirmwareMajor", 16, 8, "Firmware major version"),
            Signal::new("FirmwareMinor", 24, 8, "Firmware minor version"),
            Signal::new("FirmwarePatch", 32, 8, "Firmware patch version"),
            Signal::new("ActuatorCount", 40, 8, "Actuators driven, 1..8"),
        ],
    },
    MessageDef {
        code: Code::Capabilities,
        comment: "Stroke, speed and acceleration limits of a node's actuators",
        cycle_ms: None,
        signals: &[
            Signal::new("Stroke", 0, 16, "Stroke: targets lie in 0..stroke").unit("mm", 2),
            Signal::new("MaxSpeed", 16, 16, "Highest speed").unit(SPEED, 2),
            Signal::new("MaxAccel", 32, 16, "Highest acceleration").unit(ACCEL, 1),
        ],
    },
    MessageDef {
        code: Code::ParamRead,
        comment: "Read a parameter; answered by ParamValue or Ack",
        cycle_ms: None,
        signals: &[PARAM, ACTUATOR],
    },
    MessageDef {
        code: Code::ParamWrite,
        comment: "Write a parameter; answered by Ack",
        cycle_ms: None,
        signals: &[PARAM, ACTUATOR, VALUE],
    },
    MessageDef {
        code: Code::ParamValue,
        comment: "A parameter's value",
        cycle_ms: None,
        signals: &[PARAM, ACTUATOR, VALUE],
    },
    MessageDef {
        code: Code::Ack,
        comment: "The outcome of a request",
        cycle_ms: None,
        signals: &[
            Signal::new("Request", 0, 8, "Function code of the request").choices(&CODES),
            Signal::new("Status", 8, 8, "Outcome").choices(STATUSES),
        ],
    },
    MessageDef {
        code: Code::ForceLower,
        comment: "Measured forces of actuators 0..3 (protocol 1.1; cyclic on classic CAN)",
        cycle_ms: Some(FEEDBACK_PERIOD_MS),
        signals: &[
            force("Force0", 0),
            force("Force1", 16),
            force("Force2", 32),
            force("Force3", 48),
        ],
    },
    MessageDef {
        code: Code::ForceUpper,
        comment: "Measured forces of actuators 4..7 (protocol 1.1; cyclic on classic CAN)",
        cycle_ms: Some(FEEDBACK_PERIOD_MS),
        signals: &[
            force("Force4", 0),
            force("Force5", 16),
            force("Force6", 32),
            force("Force7", 48),
        ],
    },
    MessageDef {
        code: Code::AllForce,
        comment: "Measured forces of actuators 0..7 (protocol 1.1; cyclic on CAN FD, instead of the halves)",
        cycle_ms: Some(FEEDBACK_PERIOD_MS),
        signals: &[
            force("Force0", 0),
            force("Force1", 16),
            force("Force2", 32),
            force("Force3", 48),
            force("Force4", 64),
            force("Force5", 80),
            force("Force6", 96),
            force("Force7", 112),
        ],
    },
];

/// The DBC description of the messages with `code`.
pub const fn definition(code: Code) -> &'static MessageDef {
    &MESSAGES[code as usize]
}

/// A message's raw signal values, in the order of [`definition`]`(code).signals`.
pub fn signal_values(message: &Message) -> heapless::Vec<i64, MAX_SIGNALS> {
    let mut values = heapless::Vec::new();
    let mut push = |raws: &[i64]| {
        for &raw in raws {
            // No message has more than MAX_SIGNALS signals (checked by a test).
            let _ = values.push(raw);
        }
    };
    let position = |p| i64::from(position_to_wire(p));
    match message {
        Message::EmergencyStop | Message::IdentifyRequest => {}
        Message::Sync(m) => push(&[m.duration_ms.into()]),
        Message::Emergency(m) => {
            push(&[m.code.0.into(), actuator_to_wire(m.actuator).into(), m.detail.into()]);
        }
        Message::Targets(m) | Message::Feedback(m) => push(&m.positions.map(position)),
        Message::AllTargets(m) | Message::AllFeedback(m) => push(&m.positions.map(position)),
        Message::HostHeartbeat(m) => push(&[m.protocol.major.into(), m.protocol.minor.into()]),
        Message::Heartbeat(m) => {
            push(&[m.state as i64]);
            // One signal per defined fault bit, then one for the reserved bits above them.
            let (faults, defined) = (m.faults.bits(), Faults::all().bits().count_ones());
            for bit in 0..defined {
                push(&[((faults >> bit) & 1).into()]);
            }
            push(&[(faults >> defined).into()]);
            push(&[m.homed.bits().into(), m.moving.bits().into(), m.staged.bits().into()]);
        }
        Message::Control(command) => push(&[*command as i64]),
        Message::Home(actuators) => push(&[actuators.bits().into()]),
        Message::MotionLimits(m) => {
            let (speed, accel) = (m.max_speed.hundredths_mm_s(), m.max_accel.tenths_mm_s2());
            push(&[m.actuators.bits().into(), speed.into(), accel.into()]);
        }
        Message::Identity(m) => push(&[
            m.protocol.major.into(),
            m.protocol.minor.into(),
            m.firmware.major.into(),
            m.firmware.minor.into(),
            m.firmware.patch.into(),
            m.actuator_count.into(),
        ]),
        Message::Capabilities(m) => {
            let (speed, accel) = (m.max_speed.hundredths_mm_s(), m.max_accel.tenths_mm_s2());
            push(&[m.stroke.hundredths_mm().into(), speed.into(), accel.into()]);
        }
        Message::ParamRead(m) => push(&[m.param.0.into(), actuator_to_wire(m.actuator).into()]),
        Message::ParamWrite(m) | Message::ParamValue(m) => {
            push(&[m.param.0.into(), actuator_to_wire(m.actuator).into(), m.value.into()]);
        }
        Message::Ack(m) => push(&[m.request as i64, m.status as i64]),
        Message::Force(m) => push(&m.forces.map(|f| i64::from(force_to_wire(f)))),
        Message::AllForce(m) => push(&m.forces.map(|f| i64::from(force_to_wire(f)))),
    }
    values
}

/// A raw value scaled by 10^-decimals, printed exactly (no float rounding).
struct Scaled(i64, u8);

impl fmt::Display for Scaled {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let Scaled(raw, decimals) = *self;
        let unit = 10u64.pow(decimals.into());
        let sign = if raw < 0 { "-" } else { "" };
        let (whole, mut frac) = (raw.unsigned_abs() / unit, raw.unsigned_abs() % unit);
        if frac == 0 {
            return write!(f, "{sign}{whole}");
        }
        let mut width = usize::from(decimals);
        while frac % 10 == 0 {
            frac /= 10;
            width -= 1;
        }
        write!(f, "{sign}{whole}.{frac:0width$}")
    }
}

/// One CAN message of the DBC: a code with a concrete address.
struct DbcMessage {
    code: Code,
    address: Address,
}

impl DbcMessage {
    fn id(&self) -> u16 {
        crate::can::id(self.code, self.address).as_raw()
    }

    fn name(&self, f: &mut impl Write) -> fmt::Result {
        match (self.code.addressing(), self.address) {
            (Addressing::Broadcast, _) => write!(f, "{}", self.code.name()),
            (_, Address::Broadcast) => write!(f, "{}_All", self.code.name()),
            (_, Address::Node(node)) => write!(f, "{}_N{}", self.code.name(), node.get()),
        }
    }

    fn transmitter(&self, f: &mut impl Write) -> fmt::Result {
        match (self.code.direction(), self.address) {
            (Direction::NodeToHost, Address::Node(node)) => write!(f, "Node{}", node.get()),
            _ => write!(f, "Host"),
        }
    }

    fn receivers(&self, f: &mut impl Write, nodes: u8) -> fmt::Result {
        match (self.code.direction(), self.address) {
            (Direction::NodeToHost, _) => write!(f, "Host"),
            (Direction::HostToNode, Address::Node(node)) => write!(f, "Node{}", node.get()),
            (Direction::HostToNode, Address::Broadcast) => {
                for node in 1..=nodes {
                    let sep = if node == 1 { "" } else { "," };
                    write!(f, "{sep}Node{node}")?;
                }
                Ok(())
            }
        }
    }
}

/// The CAN messages of a form with nodes 1..=`nodes`, in id order.
fn dbc_messages(nodes: u8) -> impl Iterator<Item = DbcMessage> {
    let node_addresses = (1..=nodes).filter_map(NodeId::new).map(Address::Node);
    Code::ALL.into_iter().flat_map(move |code| {
        let broadcast = match code.addressing() {
            Addressing::Node => None,
            Addressing::Broadcast | Addressing::NodeOrBroadcast => Some(Address::Broadcast),
        };
        let nodes = match code.addressing() {
            Addressing::Broadcast => None,
            Addressing::Node | Addressing::NodeOrBroadcast => Some(node_addresses.clone()),
        };
        broadcast
            .into_iter()
            .chain(nodes.into_iter().flatten())
            .map(move |address| DbcMessage { code, address })
    })
}

/// Writes the DBC file for a form with nodes 1..=`nodes` (at most 63).
pub fn write(f: &mut impl Write, nodes: u8) -> fmt::Result {
    let nodes = nodes.min(NodeId::MAX.get());
    let ProtocolVersion { major, minor } = PROTOCOL_VERSION;
    writeln!(f, "VERSION \"dressform firmware-protocol {major}.{minor}\"")?;
    writeln!(f, "\n\nNS_ :\n\tCM_\n\tBA_DEF_\n\tBA_\n\tVAL_\n\tBA_DEF_DEF_\n\nBS_:\n")?;
    write!(f, "BU_: Host")?;
    for node in 1..=nodes {
        write!(f, " Node{node}")?;
    }
    writeln!(f, "\n")?;

    for m in dbc_messages(nodes) {
        let def = definition(m.code);
        write!(f, "\nBO_ {} ", m.id())?;
        m.name(f)?;
        write!(f, ": {} ", m.code.payload_len())?;
        m.transmitter(f)?;
        writeln!(f)?;
        for s in def.signals {
            let (min, max) = s.raw_range();
            let sign = if s.signed { '-' } else { '+' };
            write!(f, " SG_ {} : {}|{}@1{sign} ", s.name, s.start, s.len)?;
            write!(f, "({},0) ", Scaled(1, s.decimals))?;
            write!(f, "[{}|{}] ", Scaled(min, s.decimals), Scaled(max, s.decimals))?;
            write!(f, "\"{}\" ", s.unit)?;
            m.receivers(f, nodes)?;
            writeln!(f)?;
        }
    }

    writeln!(f, "\n")?;
    writeln!(
        f,
        "CM_ \"The wire contract between the dressform host and the nodes of the robotic dress form (README: firmware-protocol/README.md). Nodes 1..{nodes}.\";"
    )?;
    for m in dbc_messages(nodes) {
        let def = definition(m.code);
        writeln!(f, "CM_ BO_ {} \"{}\";", m.id(), def.comment)?;
        for s in def.signals {
            writeln!(f, "CM_ SG_ {} {} \"{}\";", m.id(), s.name, s.comment)?;
        }
    }

    writeln!(f, "BA_DEF_ \"BusType\" STRING ;")?;
    writeln!(f, "BA_DEF_ BO_ \"GenMsgCycleTime\" INT 0 65535;")?;
    write!(
        f,
        "BA_DEF_ BO_ \"VFrameFormat\" ENUM \"StandardCAN\",\"ExtendedCAN\",\"reserved\",\"J1939PG\""
    )?;
    for _ in 0..10 {
        write!(f, ",\"reserved\"")?;
    }
    writeln!(f, ",\"StandardCAN_FD\",\"ExtendedCAN_FD\";")?;
    writeln!(f, "BA_DEF_ BO_ \"CANFD_BRS\" ENUM \"0\",\"1\";")?;
    writeln!(f, "BA_DEF_DEF_ \"BusType\" \"CAN\";")?;
    writeln!(f, "BA_DEF_DEF_ \"GenMsgCycleTime\" 0;")?;
    writeln!(f, "BA_DEF_DEF_ \"VFrameFormat\" \"StandardCAN\";")?;
    writeln!(f, "BA_DEF_DEF_ \"CANFD_BRS\" \"1\";")?;
    writeln!(f, "BA_ \"BusType\" \"CAN FD\";")?;
    for m in dbc_messages(nodes) {
        let def = definition(m.code);
        let cyclic = matches!(
            (m.code.direction(), m.address),
            (Direction::NodeToHost, _) | (_, Address::Broadcast)
        );
        if let (Some(cycle), true) = (def.cycle_ms, cyclic) {
            writeln!(f, "BA_ \"GenMsgCycleTime\" BO_ {} {cycle};", m.id())?;
        }
        if m.code.payload_len() > crate::can::CLASSIC_MAX_LEN {
            writeln!(f, "BA_ \"VFrameFormat\" BO_ {} 14;", m.id())?;
        }
    }

    for m in dbc_messages(nodes) {
        for s in definition(m.code).signals.iter().filter(|s| !s.choices.is_empty()) {
            write!(f, "VAL_ {} {}", m.id(), s.name)?;
            for (value, name) in s.choices {
                write!(f, " {value} \"{name}\"")?;
            }
            writeln!(f, " ;")?;
        }
    }
    Ok(())
}
