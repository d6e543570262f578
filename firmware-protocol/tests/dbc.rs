//! The DBC file is generated from the Rust types, describes exactly the bytes the encoder
//! writes, and the committed `dressform.dbc` is the generated one.

use crate::strategies;

use std::path::Path;

use firmware_protocol::dbc::{self, MAX_SIGNALS, MESSAGES, Signal};
use firmware_protocol::drive::{AckStatus, DriveCommand, DriveState, Faults};
use firmware_protocol::{Code, can};
use proptest::prelude::*;

const COMMITTED: &str = "dressform.dbc";
/// The reference form: 9 nodes (8 of panels, 1 of lifts).
const NODES: u8 = 9;

#[test]
fn the_committed_dbc_is_the_generated_one() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(COMMITTED);
    let mut generated = String::new();
    dbc::write(&mut generated, NODES).unwrap();
    if std::env::var_os("DRESSFORM_BLESS").is_some() {
        std::fs::write(&path, &generated).unwrap();
    }
    let committed = std::fs::read_to_string(&path).unwrap_or_default();
    assert!(
        committed == generated,
        "{} is out of date with the Rust types; regenerate it with\n  \
         DRESSFORM_BLESS=1 cargo test -p firmware-protocol --test main dbc\n\
         (or: cargo run -p firmware-protocol --example dbc > firmware-protocol/{COMMITTED})",
        path.display()
    );
}

#[test]
fn definitions_follow_the_codes_and_cover_every_payload_bit_once() {
    for (def, code) in MESSAGES.iter().zip(Code::ALL) {
        assert_eq!(def.code, code);
        assert!(def.signals.len() <= MAX_SIGNALS, "{code:?}");
        let mut covered = vec![0u8; code.payload_len() * 8];
        for s in def.signals {
            let bits = usize::from(s.start)..usize::from(s.start) + usize::from(s.len);
            assert!(bits.end <= covered.len(), "{code:?} {} past the payload", s.name);
            covered[bits].iter_mut().for_each(|c| *c += 1);
        }
        assert!(covered.iter().all(|&c| c == 1), "{code:?}: bits covered {covered:?}");
    }
}

/// The choice names of the signal `name` in `code`'s message.
fn choices(code: Code, name: &str) -> &'static [(i64, &'static str)] {
    dbc::definition(code).signals.iter().find(|s| s.name == name).unwrap().choices
}

#[test]
fn value_names_match_the_rust_enums() {
    let debug_names = |values: &[(i64, &str)], name: &dyn Fn(u8) -> Option<String>| {
        for &(value, label) in values {
            assert_eq!(name(value as u8).as_deref(), Some(label));
        }
    };
    let states = choices(Code::Heartbeat, "State");
    assert_eq!(states.len(), DriveState::ALL.len());
    debug_names(states, &|v| DriveState::from_u8(v).map(|s| format!("{s:?}")));
    let commands = choices(Code::Control, "Command");
    assert_eq!(commands.len(), DriveCommand::ALL.len());
    debug_names(commands, &|v| DriveCommand::from_u8(v).map(|c| format!("{c:?}")));
    let statuses = choices(Code::Ack, "Status");
    assert_eq!(statuses.len(), AckStatus::ALL.len());
    debug_names(statuses, &|v| AckStatus::from_u8(v).map(|s| format!("{s:?}")));
}

#[test]
fn fault_signals_match_the_fault_flags() {
    let heartbeat = dbc::definition(Code::Heartbeat).signals;
    for (name, flag) in Faults::all().iter_names() {
        let camel: String =
            name.split('_').map(|w| w[..1].to_string() + &w[1..].to_lowercase()).collect();
        let start = 8 + flag.bits().trailing_zeros() as u16;
        let signal = heartbeat.iter().find(|s| s.start == start).unwrap();
        assert_eq!((signal.name, signal.len), (format!("Fault{camel}").as_str(), 1));
    }
}

/// The raw value of `signal` in `data` (Intel bit order).
fn extract(signal: &Signal, data: &[u8]) -> i64 {
    let mut raw: u64 = 0;
    for i in 0..u64::from(signal.len) {
        let bit = u64::from(signal.start) + i;
        raw |= u64::from(data[(bit / 8) as usize] >> (bit % 8) & 1) << i;
    }
    let shift = 64 - u32::from(signal.len);
    if signal.signed { ((raw << shift) as i64) >> shift } else { raw as i64 }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(2000))]

    #[test]
    fn the_encoder_puts_every_signal_where_the_dbc_says(packet in strategies::packet(1..=63)) {
        let frame = can::encode(&packet).unwrap();
        let def = dbc::definition(packet.message.code());
        let values = dbc::signal_values(&packet.message);
        prop_assert_eq!(values.len(), def.signals.len());
        for (signal, value) in def.signals.iter().zip(values) {
            prop_assert_eq!(extract(signal, embedded_can::Frame::data(&frame)), value, "{}", signal.name);
        }
    }
}
