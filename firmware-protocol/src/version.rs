//! Protocol and firmware versions, and what a host does with a node of another version.
//!
//! The protocol version is `major.minor`:
//! * a **minor** version only adds: new function codes, parameters, emergency codes, fault bits
//!   and fields appended at the end of a payload. Existing layouts and meanings never change,
//!   receivers ignore bytes past the payload they know and frames with codes they do not
//!   know; a host sends a node only what the node's minor version has.
//! * a **major** version may change anything, except the frozen subset that lets any host
//!   find and stop any node: `EmergencyStop` (CAN id 0x000), `IdentifyRequest` and `Identity`
//!   (codes and layouts fixed forever).
//!
//! The host learns a node's version from `Identity`; nodes learn the host's from its
//! heartbeat. See [`ProtocolVersion::compatibility`].

/// The protocol version this crate implements.
pub const PROTOCOL_VERSION: ProtocolVersion = ProtocolVersion { major: 1, minor: 1 };

/// Protocol 1.0: positions, the drive state machine and parameters, without force.
pub const PROTOCOL_1_0: ProtocolVersion = ProtocolVersion { major: 1, minor: 0 };

/// A protocol version, `major.minor`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct ProtocolVersion {
    /// Incompatible changes.
    pub major: u8,
    /// Compatible additions.
    pub minor: u8,
}

/// How a host may use a node (or a node its host), from their protocol versions.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Compatibility {
    /// Same major version: use the messages and parameters of `major.common_minor`, the
    /// older of the two minors.
    Compatible {
        /// The older of the two minor versions.
        common_minor: u8,
    },
    /// Different major version. A host leaves such a node Disabled, reports it, and sends
    /// it nothing but `EmergencyStop` and `IdentifyRequest`; a node answers `Enable` from
    /// such a host with `Ack` `IncompatibleVersion`.
    Incompatible,
}

impl ProtocolVersion {
    /// Whether a peer of this version measures and reports forces (`Force`, `AllForce`,
    /// `ForceLimit`, `OVER_FORCE`): since 1.1.
    pub const fn has_force(self) -> bool {
        self.major > 1 || (self.major == 1 && self.minor >= 1)
    }

    /// How `self` (say, the host) may talk to a peer speaking `peer`.
    pub const fn compatibility(self, peer: ProtocolVersion) -> Compatibility {
        if self.major != peer.major {
            Compatibility::Incompatible
        } else if self.minor < peer.minor {
            Compatibility::Compatible { common_minor: self.minor }
        } else {
            Compatibility::Compatible { common_minor: peer.minor }
        }
    }
}

/// A node's firmware version, `major.minor.patch` (the firmware's own numbering, reported
/// in `Identity`; unrelated to the protocol version).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct FirmwareVersion {
    /// Major.
    pub major: u8,
    /// Minor.
    pub minor: u8,
    /// Patch.
    pub patch: u8,
}

#[cfg(test)]
mod tests {
    use super::*;

    const fn v(major: u8, minor: u8) -> ProtocolVersion {
        ProtocolVersion { major, minor }
    }

    #[test]
    fn same_major_uses_the_older_minor_either_way() {
        assert_eq!(v(1, 3).compatibility(v(1, 1)), Compatibility::Compatible { common_minor: 1 });
        assert_eq!(v(1, 1).compatibility(v(1, 3)), Compatibility::Compatible { common_minor: 1 });
        assert_eq!(v(1, 0).compatibility(v(1, 0)), Compatibility::Compatible { common_minor: 0 });
    }

    #[test]
    fn force_arrived_in_1_1() {
        assert!(!PROTOCOL_1_0.has_force());
        assert!(PROTOCOL_VERSION.has_force() && v(1, 4).has_force());
    }

    #[test]
    fn another_major_is_incompatible_whatever_the_minors() {
        assert_eq!(v(1, 0).compatibility(v(2, 0)), Compatibility::Incompatible);
        assert_eq!(v(2, 5).compatibility(v(1, 5)), Compatibility::Incompatible);
    }
}
