//! `can::decode` on any frame a driver could deliver: the first two bytes pick the id (11
//! bits), and whether it is extended or remote; the rest is the data (up to 64 bytes).
//! A frame that decodes must re-encode to the same id and a prefix of the same data.
#![no_main]

use embedded_can::{ExtendedId, Frame as _, Id, StandardId};
use firmware_protocol::can;
use libfuzzer_sys::fuzz_target;

struct AnyFrame {
    id: Id,
    remote: bool,
    data: Vec<u8>,
}

impl embedded_can::Frame for AnyFrame {
    fn new(id: impl Into<Id>, data: &[u8]) -> Option<Self> {
        Some(Self { id: id.into(), remote: false, data: data.to_vec() })
    }
    fn new_remote(id: impl Into<Id>, dlc: usize) -> Option<Self> {
        Some(Self { id: id.into(), remote: true, data: vec![0; dlc] })
    }
    fn is_extended(&self) -> bool {
        matches!(self.id, Id::Extended(_))
    }
    fn is_remote_frame(&self) -> bool {
        self.remote
    }
    fn id(&self) -> Id {
        self.id
    }
    fn dlc(&self) -> usize {
        self.data.len()
    }
    fn data(&self) -> &[u8] {
        &self.data
    }
}

fuzz_target!(|input: &[u8]| {
    let Some((head, data)) = input.split_first_chunk::<2>() else { return };
    let head = u16::from_le_bytes(*head);
    let raw = head & 0x7FF;
    let id = match head & 0x800 {
        0 => Id::Standard(StandardId::new(raw).unwrap()),
        _ => Id::Extended(ExtendedId::new(u32::from(raw)).unwrap()),
    };
    let frame =
        AnyFrame { id, remote: head & 0x1000 != 0, data: data[..data.len().min(64)].to_vec() };
    if let Ok(packet) = can::decode(&frame) {
        let again = can::encode(&packet).expect("a decoded packet encodes");
        assert_eq!(again.id(), frame.id());
        assert!(frame.data().starts_with(again.data()));
        assert_eq!(can::decode(&again), Ok(packet));
    }
});
