//! What the nodes report, in words: drive states, fault flags, emergency events and refusals
//! — every user-facing message of the controller takes its wording from here (never Rust's
//! debug text) — and which latched faults the host may clear on its own.
//!
//! **Clearing** (CiA 402: a fault is cleared only by an explicit FaultReset from the host):
//! an emergency stop and a host timeout are latched by the host's own side (someone pressed
//! the e-stop, the host went quiet), so `drive` clears them at start
//! ([`CLEARED_AT_START`]); every other flag is the hardware's (a jam, an overcurrent, a broken
//! encoder...) and is cleared only on request (`--reset-faults`, `dressform reset`).

use std::fmt;

use firmware_protocol::drive::{AckStatus, DriveState, EmergencyCode, Faults};
use firmware_protocol::{HUNDREDTHS_PER_MM, HUNDREDTHS_PER_N};

/// Faults a drive clears at start on its own: latched by a stop or by the host, not by the
/// hardware.
pub const CLEARED_AT_START: Faults = Faults::EMERGENCY_STOP.union(Faults::HOST_TIMEOUT);

/// Every fault flag, the reserved bits included: what `reset_faults` may clear (`dressform
/// reset`, `--reset-faults`).
pub(super) const ANY_FAULT: Faults = Faults::from_bits_retain(u16::MAX);

/// The name of a drive state.
pub fn state_name(state: DriveState) -> &'static str {
    match state {
        DriveState::Disabled => "Disabled",
        DriveState::Enabled => "Enabled",
        DriveState::Homing => "Homing",
        DriveState::Fault => "Fault",
    }
}

/// The names of latched fault flags (`EMERGENCY_STOP`, ...), as the protocol spells them.
pub fn fault_names(faults: Faults) -> Vec<String> {
    let mut names: Vec<String> = faults.iter_names().map(|(name, _)| name.to_string()).collect();
    let unknown = faults.bits() & !Faults::all().bits();
    if unknown != 0 {
        names.push(format!("reserved bits 0x{unknown:04X}"));
    }
    names
}

/// What one fault flag means.
fn flag_words(flag: Faults) -> &'static str {
    const WORDS: [(Faults, &str); 11] = [
        (Faults::EMERGENCY_STOP, "emergency stop"),
        (Faults::HOST_TIMEOUT, "host timeout (the host fell silent)"),
        (Faults::OVERCURRENT, "overcurrent"),
        (
            Faults::FOLLOWING_ERROR,
            "following error (a panel lagged its plan: jammed, or its encoder failed)",
        ),
        (Faults::OVERTEMPERATURE, "overtemperature"),
        (Faults::UNDERVOLTAGE, "undervoltage"),
        (Faults::OVERVOLTAGE, "overvoltage"),
        (Faults::LIMIT_SWITCH, "limit switch hit outside homing"),
        (Faults::HOMING_FAILED, "homing failed (no home switch found)"),
        (Faults::INTERNAL, "internal firmware error"),
        (
            Faults::OVER_FORCE,
            "over its force limit (a panel pushed harder than allowed: a garment too tight, \
             or something in its way)",
        ),
    ];
    WORDS.iter().find(|(f, _)| *f == flag).map_or("a fault this host does not know", |(_, w)| w)
}

/// Latched faults in words: `emergency stop, host timeout (the host fell silent)`.
pub fn describe(faults: Faults) -> String {
    let mut words: Vec<&str> = faults.iter().map(flag_words).collect();
    if faults.bits() & !Faults::all().bits() != 0 {
        words.push(flag_words(Faults::empty()));
    }
    if words.is_empty() { "no fault".into() } else { words.join(", ") }
}

/// The protocol's name of an emergency code (`FollowingError`), or its number.
pub fn code_name(code: EmergencyCode) -> String {
    EmergencyCode::KNOWN
        .iter()
        .find(|(c, _)| *c == code)
        .map_or_else(|| format!("unknown code 0x{:04X}", code.0), |(_, name)| (*name).to_string())
}

/// Tenths of a degree in one: an over-temperature's detail is in 0.1 °C
/// ([`EmergencyCode::OVERTEMPERATURE`]).
const TENTHS_PER_DEGREE: f64 = 10.0;

/// An emergency event in words, with its detail in its unit: `following error of 1.23 mm`.
pub fn event_words(code: EmergencyCode, detail: i32) -> String {
    let mm = |hundredths: i32| format!("{:.2} mm", f64::from(hundredths) / HUNDREDTHS_PER_MM);
    match code {
        EmergencyCode::FOLLOWING_ERROR => {
            format!("following error of {} (jammed, or its encoder failed)", mm(detail))
        }
        EmergencyCode::HOST_TIMEOUT => format!("host timeout: no host heartbeat for {detail} ms"),
        EmergencyCode::OVERCURRENT => format!("overcurrent: {detail} mA"),
        EmergencyCode::OVERTEMPERATURE => {
            format!("overtemperature: {:.1} °C", f64::from(detail) / TENTHS_PER_DEGREE)
        }
        EmergencyCode::UNDERVOLTAGE => format!("undervoltage: {detail} mV"),
        EmergencyCode::OVERVOLTAGE => format!("overvoltage: {detail} mV"),
        EmergencyCode::LIMIT_SWITCH => format!("limit switch hit at {}", mm(detail)),
        EmergencyCode::HOMING_FAILED => {
            format!("homing failed: no home switch after {}", mm(detail))
        }
        EmergencyCode::EMERGENCY_STOP => "emergency stop".into(),
        EmergencyCode::OVER_FORCE => format!(
            "over its force limit: it felt {:.2} N and stopped (a garment too tight, or \
             something in its way)",
            f64::from(detail) / HUNDREDTHS_PER_N
        ),
        EmergencyCode::INTERNAL => format!("internal firmware error (detail {detail})"),
        EmergencyCode::TARGET_OUT_OF_RANGE => format!("target {} out of range", mm(detail)),
        EmergencyCode::NOT_HOMED => "target refused: not homed".into(),
        EmergencyCode::DURATION_TOO_SHORT => {
            format!("move too short for its limits: it needs {detail} ms")
        }
        other => format!("{} (detail {detail})", code_name(other)),
    }
}

/// A node's refusal in words.
pub fn refusal_words(status: AckStatus) -> &'static str {
    match status {
        AckStatus::Ok => "accepted",
        AckStatus::UnsupportedMessage => "not supported by the node",
        AckStatus::InvalidState => "not allowed in the node's state",
        AckStatus::InvalidArgument => "an argument out of range",
        AckStatus::UnknownParameter => "unknown parameter",
        AckStatus::ReadOnlyParameter => "read-only parameter",
        AckStatus::IncompatibleVersion => "another protocol major version",
    }
}

/// A node as messages name it: `node 2 (chest)`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct NodeName {
    /// Its address.
    pub address: u8,
    /// Its label in the form description.
    pub label: Option<String>,
}

impl fmt::Display for NodeName {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match &self.label {
            Some(label) => write!(f, "node {} ({label})", self.address),
            None => write!(f, "node {}", self.address),
        }
    }
}

/// A fault that stopped the form: which node and actuator, and what happened.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Fault {
    /// The node.
    pub node: NodeName,
    /// The actuator's id, when the node named one.
    pub actuator: Option<String>,
    /// What happened, in words.
    pub what: String,
}

impl fmt::Display for Fault {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.node)?;
        if let Some(actuator) = &self.actuator {
            write!(f, ", actuator {actuator}")?;
        }
        write!(f, ": {}", self.what)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn faults_read_as_words_not_debug_text() {
        let both = Faults::EMERGENCY_STOP | Faults::FOLLOWING_ERROR;
        let text = describe(both);
        assert!(text.starts_with("emergency stop, following error"), "{text}");
        assert_eq!(describe(Faults::empty()), "no fault");
        assert!(describe(Faults::from_bits_retain(1 << 12)).contains("does not know"));
        assert_eq!(fault_names(both), ["EMERGENCY_STOP", "FOLLOWING_ERROR"]);
        let words = event_words(EmergencyCode::FOLLOWING_ERROR, 123);
        assert!(words.contains("1.23 mm"), "{words}");
        assert_eq!(code_name(EmergencyCode(0x1234)), "unknown code 0x1234");
        let fault = Fault {
            node: NodeName { address: 2, label: Some("chest".into()) },
            actuator: Some("chest-l1".into()),
            what: words,
        };
        let text = fault.to_string();
        assert!(text.starts_with("node 2 (chest), actuator chest-l1: following error"), "{text}");
        for text in [text, describe(Faults::all())] {
            assert!(!text.contains("Some(") && !text.contains("Faults("), "{text}");
        }
        assert!(CLEARED_AT_START.contains(Faults::HOST_TIMEOUT));
        assert!(!CLEARED_AT_START.contains(Faults::FOLLOWING_ERROR));
    }
}
