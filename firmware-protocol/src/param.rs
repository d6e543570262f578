//! Node parameters, read and written with `ParamRead` / `ParamWrite` (values are `i32`).
//!
//! Ids `0x00xx` are node parameters (the message's actuator field must be "node", 0xFF);
//! ids `0x01xx` belong to one actuator (`ParamWrite` may use "node" to write all of them).
//! Ids `0x8000..=0xFFFF` are free for firmware-specific parameters. A node answers an id it
//! does not know with `Ack` `UnknownParameter`, and a value out of range with
//! `InvalidArgument`. Written values take effect at once and are lost at power-off.

/// A parameter id. The set is open: firmware may define more.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct ParamId(pub u16);

impl ParamId {
    /// Node: period of the node's cyclic heartbeat in ms (0 = only when polled); default
    /// [`HEARTBEAT_PERIOD_MS`](crate::timing::HEARTBEAT_PERIOD_MS).
    pub const HEARTBEAT_PERIOD: Self = Self(0x0001);
    /// Node: watchdog timeout in ms, 10..=60000; default
    /// [`WATCHDOG_TIMEOUT_MS`](crate::timing::WATCHDOG_TIMEOUT_MS).
    pub const WATCHDOG_TIMEOUT: Self = Self(0x0002);
    /// Node: period of cyclic position feedback (and, to a 1.1 host, forces) in ms (0 = only
    /// when polled); default
    /// [`FEEDBACK_PERIOD_MS`](crate::timing::FEEDBACK_PERIOD_MS).
    pub const FEEDBACK_PERIOD: Self = Self(0x0003);
    /// Actuator, read-only: stroke in 0.01 mm.
    pub const STROKE: Self = Self(0x0100);
    /// Actuator: lowest allowed target in 0.01 mm; default 0.
    pub const SOFT_LIMIT_MIN: Self = Self(0x0101);
    /// Actuator: highest allowed target in 0.01 mm; default the stroke.
    pub const SOFT_LIMIT_MAX: Self = Self(0x0102);
    /// Actuator: speed limit in 0.01 mm/s (also set by `MotionLimits`); default the
    /// node's capability.
    pub const MAX_SPEED: Self = Self(0x0103);
    /// Actuator: acceleration limit in 0.1 mm/s² (also set by `MotionLimits`); default the
    /// node's capability.
    pub const MAX_ACCEL: Self = Self(0x0104);
    /// Actuator: following error that raises `FOLLOWING_ERROR`, in 0.01 mm; default 100.
    pub const FOLLOWING_ERROR_LIMIT: Self = Self(0x0105);
    /// Actuator: homing speed in 0.01 mm/s; default 500.
    pub const HOMING_SPEED: Self = Self(0x0106);
    /// Actuator (protocol 1.1): the force that stalls the actuator and latches
    /// `OVER_FORCE`, in 0.01 N, 1..=the rated force; default the rated force.
    pub const FORCE_LIMIT: Self = Self(0x0107);
    /// Actuator, read-only (protocol 1.1): the rated force of its drive and sensor, 0.01 N.
    pub const RATED_FORCE: Self = Self(0x0108);

    /// The ids this version defines, with their names.
    pub const KNOWN: [(Self, &'static str); 12] = [
        (Self::HEARTBEAT_PERIOD, "HeartbeatPeriod"),
        (Self::WATCHDOG_TIMEOUT, "WatchdogTimeout"),
        (Self::FEEDBACK_PERIOD, "FeedbackPeriod"),
        (Self::STROKE, "Stroke"),
        (Self::SOFT_LIMIT_MIN, "SoftLimitMin"),
        (Self::SOFT_LIMIT_MAX, "SoftLimitMax"),
        (Self::MAX_SPEED, "MaxSpeed"),
        (Self::MAX_ACCEL, "MaxAccel"),
        (Self::FOLLOWING_ERROR_LIMIT, "FollowingErrorLimit"),
        (Self::HOMING_SPEED, "HomingSpeed"),
        (Self::FORCE_LIMIT, "ForceLimit"),
        (Self::RATED_FORCE, "RatedForce"),
    ];

    /// The protocol minor version (of major 1) that introduced this parameter: a host
    /// reads and writes only parameters of the minor version it shares with the node.
    pub const fn since_minor(self) -> u8 {
        match self {
            Self::FORCE_LIMIT | Self::RATED_FORCE => 1,
            _ => 0,
        }
    }

    /// Whether the parameter belongs to one actuator (ids `0x0100..=0x01FF`) rather than
    /// to the node.
    pub const fn is_per_actuator(self) -> bool {
        self.0 >> 8 == 0x01
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn node_and_actuator_parameters_are_told_apart_by_id() {
        assert!(!ParamId::WATCHDOG_TIMEOUT.is_per_actuator());
        assert!(ParamId::MAX_SPEED.is_per_actuator());
        assert!(!ParamId(0x8100).is_per_actuator());
    }
}
