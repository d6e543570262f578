//! Property tests: every packet round-trips through both mappings; the decoders reject, and
//! never panic on, arbitrary frames and bytes; corrupted serial frames fail their CRC.

use crate::strategies;

use embedded_can::{ExtendedId, Frame as _, Id, StandardId};
use firmware_protocol::{Code, Error, can, serial};
use proptest::collection::vec;
use proptest::prelude::*;
use proptest::strategy::ValueTree;
use proptest::test_runner::TestRunner;
use strategies::packet;

/// The properties below hold for every message only if the strategy makes every kind: a
/// new code (as the forces of 1.1) must be added to it.
#[test]
fn the_packet_strategy_makes_every_code() {
    let mut runner = TestRunner::deterministic();
    let strategy = packet(1..=63);
    let codes: Vec<Code> = (0..2000)
        .map(|_| strategy.new_tree(&mut runner).unwrap().current().message.code())
        .collect();
    for code in Code::ALL {
        assert!(codes.contains(&code), "the strategy makes no {code:?}");
    }
}

/// Any frame a CAN driver may hand over: either id kind, remote or not, 0..=64 bytes.
#[derive(Clone, Debug)]
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

fn any_frame() -> impl Strategy<Value = AnyFrame> {
    let id = prop_oneof![
        20 => (0..=0x7FFu16).prop_map(|raw| Id::Standard(StandardId::new(raw).unwrap())),
        1 => (0..=0x1FFF_FFFFu32).prop_map(|raw| Id::Extended(ExtendedId::new(raw).unwrap())),
    ];
    (id, prop::bool::weighted(0.05), vec(any::<u8>(), 0..=64))
        .prop_map(|(id, remote, data)| AnyFrame { id, remote, data })
}

fn frame() -> impl Strategy<Value = serial::Frame> {
    (packet(1..=63), any::<u8>()).prop_map(|(packet, seq)| serial::Frame { seq, packet })
}

/// The COBS-decoded bytes of a serial frame (header, payload, CRC).
fn raw(wire: &[u8]) -> Vec<u8> {
    let mut raw = vec![0; serial::MAX_RAW_LEN];
    let len = cobs::decode(&wire[..wire.len() - 1], &mut raw).unwrap().frame_size();
    raw.truncate(len);
    raw
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(2000))]

    #[test]
    fn every_packet_round_trips_through_can(packet in packet(1..=63)) {
        let frame = can::encode(&packet).unwrap();
        prop_assert_eq!(frame.data().len(), packet.message.code().payload_len());
        prop_assert_eq!(frame.is_fd(), frame.data().len() > can::CLASSIC_MAX_LEN);
        prop_assert_eq!(can::decode(&frame), Ok(packet));
    }

    #[test]
    fn every_packet_round_trips_through_serial(frame in frame()) {
        let wire = serial::encode(&frame).unwrap();
        prop_assert!(wire.len() <= serial::MAX_FRAME_LEN);
        prop_assert_eq!(wire.len(), serial::frame_len(frame.packet.message.code().payload_len()));
        prop_assert_eq!(wire.iter().position(|&b| b == 0), Some(wire.len() - 1));
        prop_assert_eq!(serial::decode(&wire[..wire.len() - 1]), Ok(frame));
        let mut decoder = serial::Decoder::new();
        prop_assert_eq!(decoder.feed(&wire).collect::<Vec<_>>(), vec![Ok(frame)]);
    }

    #[test]
    fn the_stream_decoder_does_not_care_how_bytes_are_chunked(
        frames in vec(frame(), 1..6),
        cuts in vec(any::<prop::sample::Index>(), 0..8),
    ) {
        let stream: Vec<u8> = frames.iter().flat_map(|f| serial::encode(f).unwrap()).collect();
        let mut cuts: Vec<usize> = cuts.iter().map(|c| c.index(stream.len())).collect();
        cuts.sort_unstable();
        let mut decoder = serial::Decoder::new();
        let mut decoded = Vec::new();
        let mut start = 0;
        for end in cuts.into_iter().chain([stream.len()]) {
            decoded.extend(decoder.feed(&stream[start..end]));
            start = end;
        }
        prop_assert_eq!(decoded, frames.into_iter().map(Ok).collect::<Vec<_>>());
    }

    #[test]
    fn the_stream_decoder_resynchronises_after_garbage(
        garbage in vec(any::<u8>(), 0..300),
        first in frame(),
        second in frame(),
    ) {
        let mut stream = garbage;
        stream.push(0);
        stream.extend(serial::encode(&first).unwrap());
        stream.extend(serial::encode(&second).unwrap());
        let mut decoder = serial::Decoder::new();
        let results: Vec<_> = decoder.feed(&stream).collect();
        prop_assert_eq!(&results[results.len() - 2..], &[Ok(first), Ok(second)]);
    }

    #[test]
    fn a_serial_frame_with_a_corrupted_bit_burst_fails_its_crc(
        frame in frame(),
        offset in any::<prop::sample::Index>(),
        pattern in any::<u16>(),
    ) {
        // Flip up to 16 bits within 16 consecutive bits (LSB-first order, as the reflected
        // CRC reads them), the first one always: CRC-16 detects every such burst.
        let mut raw = raw(&serial::encode(&frame).unwrap());
        let bits = raw.len() * 8;
        let start = offset.index(bits);
        let pattern = pattern | 1;
        for bit in (0..16).filter(|i| pattern >> i & 1 == 1).map(|i| start + i).filter(|&b| b < bits) {
            raw[bit / 8] ^= 1 << (bit % 8);
        }
        let mut wire = vec![0; cobs::max_encoding_length(raw.len())];
        let len = cobs::encode(&raw, &mut wire);
        prop_assert_eq!(serial::decode(&wire[..len]), Err(Error::Crc));
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(20_000))]

    #[test]
    fn the_can_decoder_rejects_or_inverts_the_encoder(frame in any_frame()) {
        match can::decode(&frame) {
            Ok(packet) => {
                let again = can::encode(&packet).unwrap();
                // The frame holds the encoding, maybe followed by bytes a newer minor adds.
                prop_assert!(frame.data().starts_with(again.data()));
                prop_assert_eq!(again.id(), frame.id());
                prop_assert_eq!(can::decode(&again), Ok(packet));
            }
            Err(Error::UnsupportedFrame) => {
                prop_assert!(frame.is_extended() || frame.is_remote_frame());
            }
            Err(_) => prop_assert!(frame.is_standard() && frame.is_data_frame()),
        }
    }

    /// Valid frames with one byte changed: near misses that reach deep into the decoder.
    #[test]
    fn near_miss_can_frames_are_rejected_or_decoded_exactly(
        packet in packet(1..=63),
        at in any::<prop::sample::Index>(),
        byte in any::<u8>(),
    ) {
        let frame = can::encode(&packet).unwrap();
        let mut data = frame.data().to_vec();
        if !data.is_empty() {
            let at = at.index(data.len());
            data[at] = byte;
        }
        let mutated = AnyFrame { id: frame.id(), remote: false, data };
        if let Ok(decoded) = can::decode(&mutated) {
            let again = can::encode(&decoded).unwrap();
            prop_assert_eq!(again.data(), mutated.data());
        }
    }

    #[test]
    fn the_serial_decoder_rejects_or_inverts_the_encoder(bytes in vec(any::<u8>(), 0..100)) {
        if let Ok(frame) = serial::decode(&bytes) {
            let again = serial::encode(&frame).unwrap();
            prop_assert_eq!(serial::decode(&again[..again.len() - 1]), Ok(frame));
        }
    }

    #[test]
    fn the_stream_decoder_takes_anything(bytes in vec(any::<u8>(), 0..400)) {
        let mut decoder = serial::Decoder::new();
        for frame in decoder.feed(&bytes).flatten() {
            let again = serial::encode(&frame).unwrap();
            prop_assert_eq!(serial::decode(&again[..again.len() - 1]), Ok(frame));
        }
    }
}
