//! The simulated form served on a real pseudo-terminal with the serial mapping: a host opens
//! the slave path with the `serialport` crate, as it would a USB adapter, and talks to the
//! nodes (real time: a few seconds in all).

use std::io::{ErrorKind, Read, Write};
use std::path::Path;
use std::time::{Duration, Instant};

use firmware_protocol::drive::{AckStatus, DriveCommand, DriveState};
use firmware_protocol::message::{Ack, HostHeartbeat, Positions8, Sync};
use firmware_protocol::{
    ActuatorSet, Address, Code, Message, NodeId, PROTOCOL_VERSION, Packet, Position, serial,
};
use form_description::reference;
use form_sim::serve::{PtyLink, ServeConfig, serve};
use serialport::SerialPort;

/// A blocking serial host.
struct Host {
    port: Box<dyn SerialPort>,
    decoder: serial::Decoder,
    seq: u8,
}

impl Host {
    fn open(path: &Path) -> Self {
        let path = path.to_str().unwrap();
        let mut port =
            serialport::new(path, 1_000_000).timeout(Duration::from_millis(10)).open().unwrap();
        // Flush the line's partial frame, as the protocol advises after opening.
        port.write_all(&[0]).unwrap();
        Self { port, decoder: serial::Decoder::new(), seq: 0 }
    }

    /// Sends a request; returns the frames answering it: once `expected` have come (within a
    /// second), or whatever came in 30 ms if none is expected.
    fn request(&mut self, packet: Packet, expected: usize) -> Vec<Packet> {
        self.seq = self.seq.wrapping_add(1);
        let wire = serial::encode(&serial::Frame { seq: self.seq, packet }).unwrap();
        self.port.write_all(&wire).unwrap();
        let wait = if expected == 0 { Duration::from_millis(30) } else { Duration::from_secs(1) };
        let deadline = Instant::now() + wait;
        let mut answer = Vec::new();
        let mut buf = [0u8; 512];
        while Instant::now() < deadline && (expected == 0 || answer.len() < expected) {
            match self.port.read(&mut buf) {
                Ok(n) => answer.extend(
                    self.decoder
                        .feed(&buf[..n])
                        .filter_map(Result::ok)
                        .filter(|f| f.seq == self.seq)
                        .map(|f| f.packet),
                ),
                Err(e) if e.kind() == ErrorKind::TimedOut => {}
                Err(e) => panic!("{e}"),
            }
        }
        answer
    }

    /// Polls a node: its heartbeat and positions.
    fn poll(&mut self, node: NodeId) -> Vec<Packet> {
        let heartbeat = Message::HostHeartbeat(HostHeartbeat { protocol: PROTOCOL_VERSION });
        self.request(Packet::node(node, heartbeat), 2)
    }
}

#[test]
fn a_host_on_the_pty_identifies_every_node() {
    let description = reference();
    let server = serve(ServeConfig::new(description.clone(), PtyLink::SerialPty)).unwrap();
    assert!(server.device_path().starts_with("/dev/pts"), "{:?}", server.device_path());
    let mut host = Host::open(server.device_path());
    for node in description.node_ids() {
        let answer = host.request(Packet::node(node, Message::IdentifyRequest), 2);
        let [
            Packet { address, message: Message::Identity(identity) },
            Packet { message: Message::Capabilities(capabilities), .. },
        ] = answer[..]
        else {
            panic!("node {}: {answer:?}", node.get())
        };
        assert_eq!(address, Address::Node(node));
        assert_eq!((identity.protocol, identity.actuator_count), (PROTOCOL_VERSION, 8));
        let actuators = description.actuators_of(node);
        let stroke = actuators.iter().map(|a| a.stroke()).min().unwrap();
        assert_eq!(capabilities.stroke, stroke);
        assert_eq!(capabilities.max_speed, actuators[0].max_speed());
    }
    // On a serial line nobody answers a broadcast.
    let answer = host.request(Packet::broadcast(Message::IdentifyRequest), 0);
    assert!(answer.is_empty(), "{answer:?}");
}

#[test]
fn garbage_on_the_line_is_skipped() {
    let server = serve(ServeConfig::new(reference(), PtyLink::SerialPty)).unwrap();
    let mut host = Host::open(server.device_path());
    let garbage: Vec<u8> =
        (0..400u32).map(|i| (i.wrapping_mul(2_654_435_761) >> 13) as u8).collect();
    host.port.write_all(&garbage).unwrap();
    host.port.write_all(&[0]).unwrap();
    let node = NodeId::new(3).unwrap();
    let answer = host.request(Packet::node(node, Message::IdentifyRequest), 2);
    assert_eq!(answer.len(), 2, "{answer:?}");
    // A second host session on the same pty works too.
    drop(host);
    let mut again = Host::open(server.device_path());
    assert_eq!(again.request(Packet::node(node, Message::IdentifyRequest), 2).len(), 2);
}

#[test]
fn a_host_enables_homes_and_moves_a_node_over_the_pty() {
    let description = reference();
    let server = serve(ServeConfig::new(description.clone(), PtyLink::SerialPty)).unwrap();
    let mut host = Host::open(server.device_path());
    let node = NodeId::new(7).unwrap();
    let ack = |request, status| Packet::node(node, Message::Ack(Ack { request, status }));
    host.poll(node);
    let enable = host.request(Packet::node(node, Message::Control(DriveCommand::Enable)), 1);
    assert_eq!(enable, [ack(Code::Control, AckStatus::Ok)]);
    let home = host.request(Packet::node(node, Message::Home(ActuatorSet::ALL)), 1);
    assert_eq!(home, [ack(Code::Home, AckStatus::Ok)]);

    let until = |host: &mut Host, done: &dyn Fn(&[Packet]) -> bool| {
        let deadline = Instant::now() + Duration::from_secs(5);
        while Instant::now() < deadline {
            if done(&host.poll(node)) {
                return true;
            }
        }
        false
    };
    let homed = |answer: &[Packet]| {
        matches!(answer.first(), Some(Packet { message: Message::Heartbeat(h), .. })
            if h.state == DriveState::Enabled && h.homed == ActuatorSet::ALL)
    };
    assert!(until(&mut host, &homed), "node 7 did not home");

    let target = Position::new(1500).unwrap();
    let targets = Positions8 { positions: [Some(target); 8] };
    assert!(host.request(Packet::node(node, Message::AllTargets(targets)), 0).is_empty());
    let sync = Packet::broadcast(Message::Sync(Sync { duration_ms: 2500 }));
    assert!(host.request(sync, 0).is_empty());
    let arrived = |answer: &[Packet]| match answer {
        [
            Packet { message: Message::Heartbeat(h), .. },
            Packet { message: Message::AllFeedback(f), .. },
            ..,
        ] => {
            h.moving.is_empty()
                && f.positions
                    .iter()
                    .all(|p| p.is_some_and(|p| p.hundredths_mm().abs_diff(1500) <= 10))
        }
        _ => false,
    };
    assert!(until(&mut host, &arrived), "node 7 did not arrive");
    for actuator in server.form().state().actuators.iter().filter(|a| a.node == node) {
        assert!((actuator.state.position_mm - 15.0).abs() < 1e-9, "{}", actuator.id);
    }
}

#[test]
fn the_serial_log_records_requests_and_answers() {
    let dir = tempfile::tempdir().unwrap();
    let log = dir.path().join("serial.log");
    let mut config = ServeConfig::new(reference(), PtyLink::SerialPty);
    config.log = Some(log.clone());
    let server = serve(config).unwrap();
    let mut host = Host::open(server.device_path());
    let node = NodeId::new(2).unwrap();
    assert_eq!(host.request(Packet::node(node, Message::IdentifyRequest), 2).len(), 2);
    server.shutdown().unwrap();
    let text = std::fs::read_to_string(&log).unwrap();
    let frames: Vec<&str> = text.lines().map(|l| l.split(' ').nth(2).unwrap()).collect();
    // IdentifyRequest to node 2, then its Identity and Capabilities (CAN ids of the packets).
    assert_eq!(frames[0], "382#");
    assert!(frames[1].starts_with("3C2#") && frames[2].starts_with("402#"), "{frames:?}");
    assert!(text.lines().all(|l| l.starts_with('(') && l.contains(") serial0 ")));
}

#[test]
fn serving_refuses_bad_faults_and_stops_when_asked() {
    let runtime = tokio::runtime::Builder::new_current_thread().enable_all().build().unwrap();
    runtime.block_on(async {
        let mut config = ServeConfig::new(reference(), PtyLink::SerialPty);
        config.faults = "node12:reboot@1s".parse().unwrap();
        let error = serve(config).unwrap_err();
        assert!(error.to_string().contains("the form has no node 12"), "{error}");
        for transport in [PtyLink::SerialPty, PtyLink::SlcanPty] {
            let server = serve(ServeConfig::new(reference(), transport)).unwrap();
            server.run_until(async {}).await.unwrap();
        }
    });
}
