//! The CAN mapping: one message per CAN 2.0A data frame (CAN FD for the 16-byte ones).
//!
//! **Identifier** (11 bits): `id = code << 6 | address`, with the 5-bit function [`Code`]
//! above the 6-bit [`Address`] (0 = broadcast, 1..=63 = node; the receiver for host → node
//! messages, the sender for node → host ones). A lower identifier wins arbitration, so the
//! code order is the priority order, for every node:
//!
//! | class          | codes  | ids             |
//! |----------------|--------|-----------------|
//! | e-stop         | 0      | 0x000           |
//! | SYNC           | 1      | 0x040           |
//! | faults         | 2      | 0x081..=0x0BF   |
//! | set-points     | 3..=5  | 0x0C1..=0x17F   |
//! | feedback       | 6..=8  | 0x181..=0x23F   |
//! | heartbeats     | 9, 10  | 0x240..=0x2BF   |
//! | configuration  | 11..=20| 0x2C0..=0x53F   |
//! | forces (1.1)   | 21..=23| 0x541..=0x5FF   |
//!
//! **Payload**: the message's [`payload`] layout, little-endian, the data
//! length equal to the layout length (at most 8 bytes). `AllTargets`, `AllFeedback` and
//! `AllForce` (16 bytes) travel in CAN FD frames, sent with bit-rate switching; every other message is a
//! classic frame. Send them only on a CAN FD bus, where every controller is FD-capable (a
//! classic controller answers an FD frame with error frames); on classic CAN use the halves.
//!
//! **Rules**: extended identifiers and remote frames are not part of the protocol and are
//! rejected; so are ids whose code is unknown (see [`Error::UnknownCode`]) or whose address
//! breaks the message's [`Addressing`](crate::message::Addressing) (e.g. 0x001..=0x03F).
//! A receiver ignores data bytes past the layout.

use embedded_can::{Id, StandardId};

use crate::Error;
use crate::message::{Address, Code, Packet};
use crate::payload;

/// Bits of the identifier that hold the address.
pub const ADDRESS_BITS: u32 = 6;
/// Most data bytes of a classic CAN frame.
pub const CLASSIC_MAX_LEN: usize = 8;
/// Most data bytes of a CAN FD frame.
pub const FD_MAX_LEN: usize = 64;

/// The identifier of a message with `code` to or from `address`.
pub const fn id(code: Code, address: Address) -> StandardId {
    let raw = (code as u16) << ADDRESS_BITS | address.to_u8() as u16;
    // Codes are below 32 and addresses below 64, so `raw` is at most 0x7FF.
    match StandardId::new(raw) {
        Some(id) => id,
        None => StandardId::MAX,
    }
}

/// A CAN frame of this protocol: a standard identifier and up to 64 data bytes, sent as a
/// CAN FD frame when it holds more than 8. Implements [`embedded_can::Frame`], so it converts
/// to any driver's frame type with `F::new(frame.id(), frame.data())`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Frame {
    id: StandardId,
    data: [u8; FD_MAX_LEN],
    len: u8,
}

impl Frame {
    /// The identifier (always a standard one; see also [`embedded_can::Frame::id`]).
    pub fn standard_id(&self) -> StandardId {
        self.id
    }

    /// Whether the frame needs CAN FD (more than 8 data bytes).
    pub fn is_fd(&self) -> bool {
        usize::from(self.len) > CLASSIC_MAX_LEN
    }
}

/// Whether `len` data bytes make a valid classic or CAN FD frame.
const fn is_valid_len(len: usize) -> bool {
    matches!(len, 0..=8 | 12 | 16 | 20 | 24 | 32 | 48 | 64)
}

impl embedded_can::Frame for Frame {
    /// A data frame; `None` for an extended id or a length no CAN FD frame has.
    fn new(id: impl Into<Id>, data: &[u8]) -> Option<Self> {
        let Id::Standard(id) = id.into() else { return None };
        if !is_valid_len(data.len()) {
            return None;
        }
        let mut frame = Frame { id, data: [0; FD_MAX_LEN], len: data.len() as u8 };
        frame.data[..data.len()].copy_from_slice(data);
        Some(frame)
    }

    /// Always `None`: the protocol has no remote frames.
    fn new_remote(_id: impl Into<Id>, _dlc: usize) -> Option<Self> {
        None
    }

    fn is_extended(&self) -> bool {
        false
    }

    fn is_remote_frame(&self) -> bool {
        false
    }

    fn id(&self) -> Id {
        Id::Standard(self.id)
    }

    /// The number of data bytes (also for CAN FD frames, whose DLC code differs).
    fn dlc(&self) -> usize {
        usize::from(self.len)
    }

    fn data(&self) -> &[u8] {
        &self.data[..usize::from(self.len)]
    }
}

/// Encodes a packet as a frame; fails only for an address the message does not allow.
pub fn encode(packet: &Packet) -> Result<Frame, Error> {
    packet.check_address()?;
    let code = packet.message.code();
    let payload = payload::encode(&packet.message);
    let bytes = payload.as_slice();
    let mut frame = Frame { id: id(code, packet.address), data: [0; FD_MAX_LEN], len: 0 };
    frame.data[..bytes.len()].copy_from_slice(bytes);
    frame.len = bytes.len() as u8;
    Ok(frame)
}

/// Decodes any driver's CAN frame (classic or FD) into a packet.
pub fn decode(frame: &impl embedded_can::Frame) -> Result<Packet, Error> {
    let Id::Standard(id) = frame.id() else { return Err(Error::UnsupportedFrame) };
    if frame.is_remote_frame() {
        return Err(Error::UnsupportedFrame);
    }
    let raw = id.as_raw();
    let code = (raw >> ADDRESS_BITS) as u8;
    let code = Code::from_u8(code).ok_or(Error::UnknownCode(code))?;
    let address =
        Address::from_u8((raw & ((1 << ADDRESS_BITS) - 1)) as u8).ok_or(Error::InvalidAddress)?;
    let packet = Packet { address, message: payload::decode(code, frame.data())? };
    packet.check_address()?;
    Ok(packet)
}

#[cfg(test)]
mod tests {
    use embedded_can::Frame as _;

    use super::*;
    use crate::message::{Message, NodeId, Positions8, Sync};

    /// The priority classes of the README, highest first.
    const CLASSES: [&[Code]; 8] = [
        &[Code::EmergencyStop],
        &[Code::Sync],
        &[Code::Emergency],
        &[Code::TargetsLower, Code::TargetsUpper, Code::AllTargets],
        &[Code::FeedbackLower, Code::FeedbackUpper, Code::AllFeedback],
        &[Code::HostHeartbeat, Code::Heartbeat],
        &[
            Code::Control,
            Code::Home,
            Code::MotionLimits,
            Code::IdentifyRequest,
            Code::Identity,
            Code::Capabilities,
            Code::ParamRead,
            Code::ParamWrite,
            Code::ParamValue,
            Code::Ack,
        ],
        &[Code::ForceLower, Code::ForceUpper, Code::AllForce],
    ];

    fn ids(codes: &[Code]) -> impl Iterator<Item = u16> + '_ {
        codes.iter().flat_map(|&code| {
            (0..=NodeId::MAX.get())
                .filter_map(Address::from_u8)
                .map(move |address| id(code, address).as_raw())
        })
    }

    #[test]
    fn every_id_of_a_class_outranks_every_id_of_the_next_class() {
        assert_eq!(CLASSES.iter().map(|c| c.len()).sum::<usize>(), Code::ALL.len());
        for pair in CLASSES.windows(2) {
            let worst_higher = ids(pair[0]).max().unwrap();
            let best_lower = ids(pair[1]).min().unwrap();
            assert!(worst_higher < best_lower, "{:?} vs {:?}", pair[0], pair[1]);
        }
    }

    #[test]
    fn ids_stay_below_the_0x7f0_range() {
        assert!(ids(&Code::ALL).all(|id| id < 0x7F0));
        assert_eq!(id(Code::EmergencyStop, Address::Broadcast).as_raw(), 0x000);
        assert_eq!(id(Code::Sync, Address::Broadcast).as_raw(), 0x040);
        // The forces of 1.1, the lowest class: 0x541 (node 1's ForceLower) ..= 0x5FF.
        let node = |n| Address::Node(NodeId::new(n).unwrap());
        assert_eq!(id(Code::ForceLower, node(1)).as_raw(), 0x541);
        assert_eq!(id(Code::AllForce, node(63)).as_raw(), 0x5FF);
        assert_eq!(ids(&Code::ALL).max(), Some(0x5FF));
    }

    #[test]
    fn sixteen_byte_messages_need_fd_and_the_rest_fit_classic() {
        let node = NodeId::new(1).unwrap();
        let all = encode(&Packet::node(node, Message::AllTargets(Positions8::default()))).unwrap();
        assert!(all.is_fd() && all.dlc() == 16);
        let sync = encode(&Packet::broadcast(Message::Sync(Sync { duration_ms: 1500 }))).unwrap();
        assert!(!sync.is_fd());
        assert_eq!(sync.data(), [0xDC, 0x05]);
        assert!(
            Code::ALL.iter().all(|c| c.payload_len() <= CLASSIC_MAX_LEN || c.payload_len() == 16)
        );
    }

    #[test]
    fn frames_accept_only_can_fd_lengths() {
        let id = StandardId::new(0x123).unwrap();
        assert!(Frame::new(id, &[0; 12]).is_some());
        assert!(Frame::new(id, &[0; 9]).is_none());
        assert!(Frame::new(embedded_can::ExtendedId::new(1).unwrap(), &[]).is_none());
        assert!(Frame::new_remote(id, 0).is_none());
    }

    #[test]
    fn reserved_ids_and_addresses_are_rejected() {
        let frame = |raw, data: &[u8]| Frame::new(StandardId::new(raw).unwrap(), data).unwrap();
        assert_eq!(decode(&frame(0x001, &[])), Err(Error::InvalidAddress));
        assert_eq!(decode(&frame(0x0C0, &[0; 8])), Err(Error::InvalidAddress));
        // Node messages from address 0: 0x540 (ForceLower), 0x5C0 (AllForce).
        assert_eq!(decode(&frame(0x540, &[0; 8])), Err(Error::InvalidAddress));
        assert_eq!(decode(&frame(0x5C0, &[0; 16])), Err(Error::InvalidAddress));
        // The first unknown code, 24: ids 0x600..=0x63F.
        assert_eq!(decode(&frame(0x600, &[])), Err(Error::UnknownCode(24)));
        assert_eq!(decode(&frame(0x7EF, &[])), Err(Error::UnknownCode(31)));
        assert_eq!(decode(&frame(0x000, &[1, 2])), Ok(Packet::broadcast(Message::EmergencyStop)));
    }
}
