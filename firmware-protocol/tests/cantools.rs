//! Cross-check with cantools, an independent DBC implementation: every frame the Rust encoder
//! writes decodes in cantools (with `dressform.dbc`) to the signal values of the Rust message,
//! and every frame cantools encodes from those values decodes in Rust to the same message.
//!
//! Needs `python3` with cantools (`python3 -m pip install cantools`). Without it the test
//! prints why and passes, unless `DRESSFORM_REQUIRE_PEERS=1` (as in CI), where it fails.

use crate::strategies;

use std::collections::BTreeMap;
use std::io::Write;
use std::path::Path;
use std::process::{Command, Stdio};

use embedded_can::Frame as _;
use firmware_protocol::{Code, Packet, can, dbc};
use proptest::strategy::{Strategy, ValueTree};
use proptest::test_runner::TestRunner;
use serde_json::{Value, json};

/// Packets checked; every code appears many times.
const CASES: usize = 4000;

fn cantools_available() -> bool {
    crate::skip::or_skip(
        crate::skip::python_modules("cantools"),
        "cantools (`python3 -m pip install cantools`)",
        "DRESSFORM_REQUIRE_PEERS",
    )
    .is_some()
}

/// Deterministic packets for the DBC's nodes 1..=9.
fn packets() -> Vec<Packet> {
    let mut runner = TestRunner::deterministic();
    let strategy = strategies::packet(1..=9);
    (0..CASES).map(|_| strategy.new_tree(&mut runner).unwrap().current()).collect()
}

/// Named signal values of a message, as the Rust types see them.
fn signals(packet: &Packet) -> BTreeMap<String, i64> {
    let def = dbc::definition(packet.message.code());
    let values = dbc::signal_values(&packet.message);
    def.signals.iter().map(|s| s.name.to_string()).zip(values).collect()
}

fn hex(bytes: &[u8]) -> String {
    bytes.iter().map(|b| format!("{b:02x}")).collect()
}

fn unhex(text: &str) -> Vec<u8> {
    (0..text.len()).step_by(2).map(|i| u8::from_str_radix(&text[i..i + 2], 16).unwrap()).collect()
}

#[test]
fn cantools_and_rust_agree_on_every_message_both_ways() {
    if !cantools_available() {
        return;
    }
    let packets = packets();
    let frames: Vec<can::Frame> = packets.iter().map(|p| can::encode(p).unwrap()).collect();
    for code in Code::ALL {
        assert!(packets.iter().any(|p| p.message.code() == code), "no {code:?} case");
    }

    let mut input = String::new();
    for (packet, frame) in packets.iter().zip(&frames) {
        let case = json!({"id": frame.standard_id().as_raw(), "data": hex(frame.data()), "signals": signals(packet)});
        input.push_str(&format!("{case}\n"));
    }
    let dir = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut child = Command::new("python3")
        .arg(dir.join("tests/cantools_check.py"))
        .arg(dir.join("dressform.dbc"))
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("python3 runs");
    let mut stdin = child.stdin.take().unwrap();
    let writer = std::thread::spawn(move || stdin.write_all(input.as_bytes()));
    let output = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(output.status.success(), "cantools_check.py failed:\n{stderr}");
    writer.join().unwrap().unwrap();

    let answers: Vec<Value> = String::from_utf8(output.stdout)
        .unwrap()
        .lines()
        .map(|line| serde_json::from_str(line).unwrap())
        .collect();
    assert_eq!(answers.len(), packets.len());
    for ((packet, frame), answer) in packets.iter().zip(&frames).zip(&answers) {
        let code = packet.message.code();
        assert_eq!(answer["length"], code.payload_len(), "{packet:?}");
        assert_eq!(answer["is_fd"], frame.is_fd(), "{packet:?}");
        assert!(answer["name"].as_str().unwrap().starts_with(code.name()), "{answer}");

        // Rust → cantools: the frame decodes to the message's signal values.
        let decoded: BTreeMap<String, i64> =
            serde_json::from_value(answer["decoded"].clone()).unwrap();
        assert_eq!(decoded, signals(packet), "cantools decodes {packet:?} differently");

        // cantools → Rust: its encoding of those values decodes to the same message.
        let encoded = unhex(answer["encoded"].as_str().unwrap());
        assert_eq!(encoded, frame.data(), "cantools encodes {packet:?} differently");
        let from_cantools = can::Frame::new(frame.id(), &encoded).unwrap();
        assert_eq!(can::decode(&from_cantools), Ok(*packet));
    }
}
