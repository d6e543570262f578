//! The drive state machine of a node (CiA 402 in spirit), its faults and its answers.
//!
//! ```text
//!   power-on
//!      │          Enable                 Home
//!      ▼     ────────────────►      ────────────────►
//!   Disabled                  Enabled                 Homing
//!      ▲     ◄────────────────      ◄────────────────
//!      │          Disable            homing done, Halt     (Disable: Homing → Disabled)
//!      │ FaultReset (no cause left)
//!    Fault ◄──── a fault, EmergencyStop or the watchdog, from any state
//! ```
//!
//! * **Disabled**: power stage off. Parameters, limits and identification work in every
//!   state.
//! * **Enabled**: power stage on; staged targets move on SYNC; `Home` starts homing.
//! * **Homing**: the actuators named by `Home` seek their home switch, then the node
//!   returns to Enabled (or to Fault with [`Faults::HOMING_FAILED`]).
//! * **Fault**: a fault sets a bit of [`Faults`] and the node sends an `Emergency` with the
//!   matching [`EmergencyCode`]; moving actuators stop at their acceleration limit (one over
//!   its force limit, [`Faults::OVER_FORCE`], at once), the power stage turns off and staged
//!   targets are dropped. `FaultReset` clears the faults whose
//!   cause is gone; when none is left the node goes to Disabled and sends `Emergency`
//!   [`EmergencyCode::NO_ERROR`].
//!
//! The full transition table, with the `Ack` of every command, is in the README.

use bitflags::bitflags;

/// The state a node reports in its heartbeat.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[repr(u8)]
pub enum DriveState {
    /// Power stage off; the state after power-on and after a fault reset.
    Disabled = 0,
    /// Power stage on, accepting SYNC moves and homing.
    Enabled = 1,
    /// Homing in progress.
    Homing = 2,
    /// A fault is latched; see the heartbeat's fault flags.
    Fault = 3,
}

impl DriveState {
    /// Every state, by wire value.
    pub const ALL: [Self; 4] = [Self::Disabled, Self::Enabled, Self::Homing, Self::Fault];

    /// The state with this wire value.
    pub const fn from_u8(raw: u8) -> Option<Self> {
        // `ALL` is in wire-value order, from 0.
        if (raw as usize) < Self::ALL.len() { Some(Self::ALL[raw as usize]) } else { None }
    }
}

/// A command of the `Control` message.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[repr(u8)]
pub enum DriveCommand {
    /// Ramp moving actuators down, then turn the power stage off (→ Disabled).
    Disable = 0,
    /// Turn the power stage on (Disabled → Enabled); refused in Fault.
    Enable = 1,
    /// Clear the faults whose cause is gone (Fault → Disabled when none is left).
    FaultReset = 2,
    /// Stop moving or homing at the configured deceleration and drop staged targets,
    /// staying Enabled.
    Halt = 3,
}

impl DriveCommand {
    /// Every command, by wire value.
    pub const ALL: [Self; 4] = [Self::Disable, Self::Enable, Self::FaultReset, Self::Halt];

    /// The command with this wire value.
    pub const fn from_u8(raw: u8) -> Option<Self> {
        // `ALL` is in wire-value order, from 0.
        if (raw as usize) < Self::ALL.len() { Some(Self::ALL[raw as usize]) } else { None }
    }
}

bitflags! {
    /// The faults latched by a node (heartbeat field, `u16`). Bits 11..=15 are reserved:
    /// senders set them to 0, receivers keep and report them (a newer minor version may
    /// define them).
    #[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
    pub struct Faults: u16 {
        /// An `EmergencyStop` was received.
        const EMERGENCY_STOP = 1 << 0;
        /// No host heartbeat within the watchdog timeout.
        const HOST_TIMEOUT = 1 << 1;
        /// A motor current exceeded its limit.
        const OVERCURRENT = 1 << 2;
        /// An actuator lagged its planned position by more than the allowed error (stall).
        const FOLLOWING_ERROR = 1 << 3;
        /// The board or a motor is too hot.
        const OVERTEMPERATURE = 1 << 4;
        /// Supply voltage too low.
        const UNDERVOLTAGE = 1 << 5;
        /// Supply voltage too high.
        const OVERVOLTAGE = 1 << 6;
        /// An end switch triggered outside homing.
        const LIMIT_SWITCH = 1 << 7;
        /// Homing did not find the home switch.
        const HOMING_FAILED = 1 << 8;
        /// Firmware error (assertion, watchdog reset, corrupted configuration).
        const INTERNAL = 1 << 9;
        /// An actuator felt more than its `ForceLimit` and stalled (protocol 1.1).
        const OVER_FORCE = 1 << 10;
    }
}

/// The code of an `Emergency` event (`u16`), with error classes as in CiA 301
/// (0x2xxx current, 0x3xxx voltage, 0x4xxx temperature, 0x6xxx software, 0x8xxx monitoring,
/// 0xFFxx device-specific). Faults latch the node in [`DriveState::Fault`]; warnings
/// (0xFF1x) only report. The set is open: a newer minor version may add codes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct EmergencyCode(pub u16);

impl EmergencyCode {
    /// All faults were cleared by `FaultReset`; the node is Disabled again.
    pub const NO_ERROR: Self = Self(0x0000);
    /// Fault: motor current over its limit; detail = current in mA.
    pub const OVERCURRENT: Self = Self(0x2310);
    /// Fault: supply over voltage; detail = voltage in mV.
    pub const OVERVOLTAGE: Self = Self(0x3110);
    /// Fault: supply under voltage; detail = voltage in mV.
    pub const UNDERVOLTAGE: Self = Self(0x3120);
    /// Fault: over temperature; detail = temperature in 0.1 °C.
    pub const OVERTEMPERATURE: Self = Self(0x4310);
    /// Fault: firmware error; detail = firmware-specific.
    pub const INTERNAL: Self = Self(0x6100);
    /// Fault: host heartbeat lost; detail = ms since the last one.
    pub const HOST_TIMEOUT: Self = Self(0x8130);
    /// Fault: following error (stall); detail = error in 0.01 mm.
    pub const FOLLOWING_ERROR: Self = Self(0x8611);
    /// Fault: end switch hit outside homing; detail = position in 0.01 mm.
    pub const LIMIT_SWITCH: Self = Self(0x8612);
    /// Fault: `EmergencyStop` received; detail = 0.
    pub const EMERGENCY_STOP: Self = Self(0xFF01);
    /// Fault: homing failed; detail = distance travelled in 0.01 mm.
    pub const HOMING_FAILED: Self = Self(0xFF02);
    /// Fault (protocol 1.1): an actuator felt more than its `ForceLimit`, stopped where it
    /// was and holds; detail = the force in 0.01 N.
    pub const OVER_FORCE: Self = Self(0xFF03);
    /// Warning: a target lies outside the actuator's soft limits and was not staged;
    /// detail = the target in 0.01 mm.
    pub const TARGET_OUT_OF_RANGE: Self = Self(0xFF10);
    /// Warning: a target for an actuator that is not homed was not staged; detail = 0.
    pub const NOT_HOMED: Self = Self(0xFF11);
    /// Warning: the SYNC duration was too short for this actuator's limits; it moves at its
    /// limits and arrives late. Detail = the shortest feasible duration in ms.
    pub const DURATION_TOO_SHORT: Self = Self(0xFF12);

    /// The codes this version defines, with their names.
    pub const KNOWN: [(Self, &'static str); 15] = [
        (Self::NO_ERROR, "NoError"),
        (Self::OVERCURRENT, "Overcurrent"),
        (Self::OVERVOLTAGE, "Overvoltage"),
        (Self::UNDERVOLTAGE, "Undervoltage"),
        (Self::OVERTEMPERATURE, "Overtemperature"),
        (Self::INTERNAL, "Internal"),
        (Self::HOST_TIMEOUT, "HostTimeout"),
        (Self::FOLLOWING_ERROR, "FollowingError"),
        (Self::LIMIT_SWITCH, "LimitSwitch"),
        (Self::EMERGENCY_STOP, "EmergencyStop"),
        (Self::HOMING_FAILED, "HomingFailed"),
        (Self::OVER_FORCE, "OverForce"),
        (Self::TARGET_OUT_OF_RANGE, "TargetOutOfRange"),
        (Self::NOT_HOMED, "NotHomed"),
        (Self::DURATION_TOO_SHORT, "DurationTooShort"),
    ];

    /// The fault flag this code latches; empty for warnings, `NO_ERROR` and unknown codes.
    pub const fn fault(self) -> Faults {
        match self {
            Self::OVERCURRENT => Faults::OVERCURRENT,
            Self::OVERVOLTAGE => Faults::OVERVOLTAGE,
            Self::UNDERVOLTAGE => Faults::UNDERVOLTAGE,
            Self::OVERTEMPERATURE => Faults::OVERTEMPERATURE,
            Self::INTERNAL => Faults::INTERNAL,
            Self::HOST_TIMEOUT => Faults::HOST_TIMEOUT,
            Self::FOLLOWING_ERROR => Faults::FOLLOWING_ERROR,
            Self::LIMIT_SWITCH => Faults::LIMIT_SWITCH,
            Self::EMERGENCY_STOP => Faults::EMERGENCY_STOP,
            Self::HOMING_FAILED => Faults::HOMING_FAILED,
            Self::OVER_FORCE => Faults::OVER_FORCE,
            _ => Faults::empty(),
        }
    }
}

/// The outcome a node reports in an `Ack`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[repr(u8)]
pub enum AckStatus {
    /// Done (or, for `Home`, started).
    Ok = 0,
    /// The node knows this request but does not implement it (e.g. `Home` on a node whose
    /// actuators have absolute encoders).
    UnsupportedMessage = 1,
    /// Not allowed in the current drive state (e.g. `Enable` in Fault, `Home` while Disabled).
    InvalidState = 2,
    /// A field is out of range for this node (an actuator it lacks, a limit above its
    /// capabilities, a parameter value out of range).
    InvalidArgument = 3,
    /// No such parameter.
    UnknownParameter = 4,
    /// The parameter cannot be written.
    ReadOnlyParameter = 5,
    /// `Enable` refused: the host heartbeat announced another protocol major version.
    IncompatibleVersion = 6,
}

impl AckStatus {
    /// Every status, by wire value.
    pub const ALL: [Self; 7] = [
        Self::Ok,
        Self::UnsupportedMessage,
        Self::InvalidState,
        Self::InvalidArgument,
        Self::UnknownParameter,
        Self::ReadOnlyParameter,
        Self::IncompatibleVersion,
    ];

    /// The status with this wire value.
    pub const fn from_u8(raw: u8) -> Option<Self> {
        // `ALL` is in wire-value order, from 0.
        if (raw as usize) < Self::ALL.len() { Some(Self::ALL[raw as usize]) } else { None }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn enums_decode_their_own_wire_values_only() {
        for s in DriveState::ALL {
            assert_eq!(DriveState::from_u8(s as u8), Some(s));
        }
        for c in DriveCommand::ALL {
            assert_eq!(DriveCommand::from_u8(c as u8), Some(c));
        }
        for a in AckStatus::ALL {
            assert_eq!(AckStatus::from_u8(a as u8), Some(a));
        }
        assert_eq!(DriveState::from_u8(DriveState::ALL.len() as u8), None);
        assert_eq!(DriveCommand::from_u8(DriveCommand::ALL.len() as u8), None);
        assert_eq!(AckStatus::from_u8(AckStatus::ALL.len() as u8), None);
    }

    #[test]
    fn every_fault_flag_has_exactly_one_emergency_code() {
        for flag in Faults::all().iter() {
            let codes: Vec<_> =
                EmergencyCode::KNOWN.iter().filter(|(c, _)| c.fault() == flag).collect();
            assert_eq!(codes.len(), 1, "{flag:?}");
        }
        assert!(EmergencyCode::NO_ERROR.fault().is_empty());
        assert!(EmergencyCode::DURATION_TOO_SHORT.fault().is_empty());
        assert!(EmergencyCode(0x1234).fault().is_empty());
    }
}
