//! The simulated form behind an slcan adapter on a real pseudo-terminal, spoken to in
//! Lawicel ASCII through the `serialport` crate (the python-can peer is in
//! `slcan_python_can.rs`).

use std::io::{ErrorKind, Read, Write};
use std::time::{Duration, Instant};

use embedded_can::{Frame as _, StandardId};
use firmware_protocol::can::Frame;
use firmware_protocol::{Code, Message, can};
use form_description::reference;
use form_sim::serve::{PtyLink, ServeConfig, Server, serve};
use serialport::SerialPort;

/// The reference form behind an slcan adapter.
fn start() -> Server {
    serve(ServeConfig::new(reference(), PtyLink::SlcanPty)).unwrap()
}

fn open(server: &Server) -> Box<dyn SerialPort> {
    let path = server.device_path().to_str().unwrap();
    serialport::new(path, 115_200).timeout(Duration::from_millis(10)).open().unwrap()
}

/// Reads `\r`- or BEL-terminated lines until `done` holds for them (or a second passes).
fn read_until(port: &mut Box<dyn SerialPort>, done: impl Fn(&[String]) -> bool) -> Vec<String> {
    let deadline = Instant::now() + Duration::from_secs(1);
    let mut text = String::new();
    let mut buf = [0u8; 4096];
    loop {
        let lines: Vec<String> = text.split_inclusive(['\r', '\x07']).map(str::to_string).collect();
        let complete = text.ends_with(['\r', '\x07']) || text.is_empty();
        if (complete && done(&lines)) || Instant::now() >= deadline {
            return lines;
        }
        match port.read(&mut buf) {
            Ok(n) => text.push_str(std::str::from_utf8(&buf[..n]).unwrap()),
            Err(e) if e.kind() == ErrorKind::TimedOut => {}
            Err(e) => panic!("{e}"),
        }
    }
}

/// The answers among `lines` (everything but received frames).
fn answers(lines: &[String]) -> Vec<&str> {
    lines.iter().map(String::as_str).filter(|l| !l.starts_with('t')).collect()
}

/// Reads until `count` answers have come; returns them.
fn read_answers(port: &mut Box<dyn SerialPort>, count: usize) -> Vec<String> {
    let lines = read_until(port, |lines| answers(lines).len() >= count);
    answers(&lines).into_iter().map(str::to_string).collect()
}

/// A `tIIILDD..` line as a frame.
fn parse(line: &str) -> Option<Frame> {
    let line = line.strip_prefix('t')?.strip_suffix('\r')?;
    let id = u16::from_str_radix(&line[..3], 16).ok()?;
    let len: usize = line[3..4].parse().ok()?;
    let data: Vec<u8> =
        (0..len).map(|i| u8::from_str_radix(&line[4 + 2 * i..6 + 2 * i], 16).unwrap()).collect();
    Frame::new(StandardId::new(id)?, &data)
}

#[test]
fn an_slcan_host_identifies_every_node() {
    let server = start();
    let mut port = open(&server);
    port.write_all(b"C\rS8\rO\r").unwrap();
    assert_eq!(read_answers(&mut port, 3), ["\r", "\r", "\r"]);
    // Broadcast IdentifyRequest: id 14 << 6 = 0x380, no data.
    port.write_all(b"t3800\r").unwrap();
    let nodes: Vec<_> = reference().node_ids().collect();
    let decode = |lines: &[String]| -> Vec<firmware_protocol::Packet> {
        lines.iter().filter_map(|l| parse(l)).filter_map(|f| can::decode(&f).ok()).collect()
    };
    let answered = |packets: &[firmware_protocol::Packet], code| {
        nodes.iter().all(|&n| {
            packets.iter().any(|p| {
                p.address == firmware_protocol::Address::Node(n) && p.message.code() == code
            })
        })
    };
    let lines = read_until(&mut port, |lines| {
        let packets = decode(lines);
        answered(&packets, Code::Identity) && answered(&packets, Code::Capabilities)
    });
    let packets = decode(&lines);
    assert!(answered(&packets, Code::Identity) && answered(&packets, Code::Capabilities));
    assert_eq!(answers(&lines), ["z\r"]);
    assert!(
        packets.iter().any(|p| matches!(p.message, Message::Identity(i) if i.actuator_count == 8))
    );
    // The nodes' cyclic traffic flows too: classic feedback halves, never FD frames.
    let lines = read_until(&mut port, |lines| {
        decode(lines).iter().any(|p| p.message.code() == Code::FeedbackUpper)
    });
    assert!(!lines.iter().any(|l| l.starts_with(['b', 'd'])));
    let stats = server.bus_stats().unwrap();
    assert!(stats.frames > 16 && stats.load() > 0.0, "{stats:?}");
}

#[test]
fn the_adapter_refuses_what_a_classic_slcan_adapter_cannot_do() {
    let server = start();
    let mut port = open(&server);
    // A wrong bit rate cannot reach the bus, so the channel does not open.
    port.write_all(b"S6\rO\r").unwrap();
    assert_eq!(read_answers(&mut port, 2), ["\x07", "\x07"]);
    port.write_all(b"S8\rO\rV\rN\rF\r").unwrap();
    assert_eq!(read_answers(&mut port, 5), ["\r", "\r", "V1013\r", "NSIM1\r", "F00\r"]);
    for refused in [
        "T123456780\r", // extended frame
        "r3800\r",      // remote frame
        "b1450\r",      // CAN FD frame
        "t38\r",        // malformed
        "t2C31G1\r",    // not hex
        "Y5\r",         // data bit rate
        "hello\r",      // not a command
    ] {
        port.write_all(refused.as_bytes()).unwrap();
        assert_eq!(read_answers(&mut port, 1), ["\x07"], "{refused}");
    }
    // An overlong line is refused once, then the adapter works again.
    port.write_all(&[b'x'; 300]).unwrap();
    port.write_all(b"\rt3830\r").unwrap();
    let lines = read_until(&mut port, |lines| {
        lines.iter().filter_map(|l| parse(l)).any(|f| f.standard_id().as_raw() == 0x3C3)
    });
    assert_eq!(answers(&lines)[..2], ["\x07", "z\r"]);
    // Closed: nothing more from the bus after the close's answer.
    port.write_all(b"C\r").unwrap();
    read_until(&mut port, |lines| lines.last().is_some_and(|l| l == "\r"));
    let after = read_until(&mut port, |_| false);
    assert!(after.is_empty(), "{after:?}");
}
