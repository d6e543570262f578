//! Writes a seed corpus for the fuzz targets: one valid frame of every message, so that the
//! fuzzers start past the CRC and the id checks. Run before fuzzing (see README, "Fuzzing"):
//!
//! ```sh
//! cargo run -p firmware-protocol --example fuzz_seeds
//! ```

use std::fs;
use std::path::Path;

use firmware_protocol::message::Addressing;
use firmware_protocol::{Address, Code, NodeId, Packet, can, payload, serial};

fn main() -> std::io::Result<()> {
    let corpus = Path::new(env!("CARGO_MANIFEST_DIR")).join("fuzz/corpus");
    let mut stream = vec![0x10]; // serial_stream's first byte: the chunk size
    for code in Code::ALL {
        // Ones decode to a valid message of every kind (all-zero would be no valid Identity).
        let message = payload::decode(code, &[1; payload::MAX_LEN]).expect("ones are valid");
        let address = match code.addressing() {
            Addressing::Broadcast => Address::Broadcast,
            _ => Address::Node(NodeId::new(5).expect("5 is a node id")),
        };
        let packet = Packet { address, message };
        let frame = can::encode(&packet).expect("a valid packet");
        let id = can::id(code, address).as_raw();
        let can_seed = [&id.to_le_bytes()[..], embedded_can::Frame::data(&frame)].concat();
        let wire = serial::encode(&serial::Frame { seq: code as u8, packet }).expect("valid");
        write(&corpus.join("can_decode"), code.name(), &can_seed)?;
        write(&corpus.join("serial_decode"), code.name(), &wire[..wire.len() - 1])?;
        stream.extend_from_slice(&wire);
    }
    write(&corpus.join("serial_stream"), "all", &stream)
}

fn write(dir: &Path, name: &str, bytes: &[u8]) -> std::io::Result<()> {
    fs::create_dir_all(dir)?;
    fs::write(dir.join(format!("seed-{name}")), bytes)
}
