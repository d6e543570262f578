//! The controller on real pseudo-terminals, as on hardware: the simulated reference form is
//! served by `form_sim::serve` (as `dressform sim` does) with the serial mapping or behind an slcan
//! adapter, and the host opens the pty's path with `serialport` (real time, a few seconds).

use std::collections::BTreeMap;
use std::path::Path;

use dressform::form::controller::session::{LINK_STALL_LIMIT, Session, SessionError};
use dressform::form::controller::transport::serial::SerialLine;
use dressform::form::controller::transport::slcan::Slcan;
use dressform::form::controller::{Connection, DriveOptions, LinkSpec, Transport, drive, status};
use dressform::form::setpoints::SetPoints;
use firmware_protocol::NodeId;
use firmware_protocol::drive::{DriveCommand, Faults};
use form_description::reference;
use form_sim::serve::{PtyLink, ServeConfig, Server, serve};
use tokio::runtime::Runtime;
use tokio::time::{Duration, Instant};

/// The reference form served on a pty of `transport` (on its own thread), and a runtime for
/// the host.
pub(crate) fn start(transport: PtyLink) -> (Runtime, Server) {
    start_with(ServeConfig::new(reference(), transport))
}

fn start_with(config: ServeConfig) -> (Runtime, Server) {
    let runtime = tokio::runtime::Builder::new_current_thread().enable_all().build().unwrap();
    (runtime, serve(config).unwrap())
}

/// A few actuators on several nodes, short moves.
fn setpoints() -> SetPoints {
    let positions: BTreeMap<String, f64> = [
        ("neck-front", 3.0),
        ("chest-l1", 4.5),
        ("chest-r1", 4.5),
        ("waist-back", 3.25),
        ("thigh-r-inner", 2.0),
    ]
    .into_iter()
    .map(|(id, mm)| (id.to_string(), mm))
    .collect();
    SetPoints::new("reference", positions)
}

fn drive_over<T: Transport>(runtime: &Runtime, server: &Server, transport: T) {
    let form = reference();
    let setpoints = setpoints();
    let report = runtime
        .block_on(drive(transport, &form, &setpoints, &DriveOptions::default(), |_| {}))
        .unwrap();
    assert!(report.converged(), "{report:?}");
    let truth = server.form().state();
    for (id, &mm) in &setpoints.positions_mm {
        let real = truth.actuator(id).unwrap().state.position_mm;
        assert!((real - mm).abs() <= 0.1, "{id}: {real} vs {mm}");
    }
}

#[test]
fn drives_the_form_over_a_serial_pty() {
    let (runtime, server) = start(PtyLink::SerialPty);
    let line = SerialLine::open(server.device_path()).unwrap();
    drive_over(&runtime, &server, line);
    // Status over the same pty afterwards: every node identified, Disabled, positions known.
    let connection = Connection::open(&LinkSpec::Serial(server.device_path().into())).unwrap();
    let form = reference();
    let nodes = runtime.block_on(status(connection, &form, Duration::from_millis(200))).unwrap();
    assert_eq!(nodes.len(), form.nodes.len());
    for node in &nodes {
        assert!(node.identified && node.problems.is_empty(), "{node:?}");
        assert_eq!(node.state.as_deref(), Some("Disabled"), "{node:?}");
    }
    let chest = nodes.iter().find(|n| n.node == 2).unwrap();
    let l1 = chest.positions_mm.iter().find(|(id, _)| id == "chest-l1").unwrap().1.unwrap();
    assert!((l1 - 4.5).abs() <= 0.1, "{l1}");
}

#[test]
fn drives_the_form_over_slcan_on_a_pty() {
    let (runtime, server) = start(PtyLink::SlcanPty);
    let slcan = Slcan::open(server.device_path()).unwrap();
    drive_over(&runtime, &server, slcan);
}

/// A host that opened the channel, asked every node to identify and went away without
/// reading leaves 16 answers in the pty; the next host does not take them for its own (it
/// clears its input on opening, as pyserial does; the simulated adapter no longer takes back
/// bytes it wrote, which raced hosts that were reading).
#[test]
fn a_host_that_went_away_leaves_no_answers_for_the_next() {
    use std::io::Write;
    let (runtime, server) = start(PtyLink::SlcanPty);
    let mut gone = serialport::new(server.device_path().to_string_lossy(), 115_200)
        .timeout(Duration::from_millis(10))
        .open()
        .unwrap();
    // IdentifyRequest (code 14) broadcast: id 14 << 6, no data.
    gone.write_all(b"S8\rO\rt3800\r").unwrap();
    // 8 Identity (6 bytes) and 8 Capabilities lines, at least `tIIIL` and `\r` each.
    let answers = 16 * 6;
    let deadline = std::time::Instant::now() + Duration::from_secs(10);
    // All of them left unread: at least `answers` bytes, then no more for `SETTLED` (the
    // answers still on their way when the host goes are answers in flight, not left over).
    const SETTLED: Duration = Duration::from_millis(200);
    let (mut seen, mut since) = (0, std::time::Instant::now());
    loop {
        let waiting = gone.bytes_to_read().unwrap();
        if waiting != seen {
            (seen, since) = (waiting, std::time::Instant::now());
        } else if seen >= answers && since.elapsed() >= SETTLED {
            break;
        }
        assert!(std::time::Instant::now() < deadline, "the nodes did not answer");
        std::thread::sleep(Duration::from_millis(10));
    }
    drop(gone);

    let mut next = Slcan::open(server.device_path()).unwrap();
    let heard = runtime.block_on(async {
        let mut heard = Vec::new();
        let listen = async {
            loop {
                heard.push(next.recv().await.unwrap().message.code());
            }
        };
        let _ = tokio::time::timeout(Duration::from_millis(300), listen).await;
        heard
    });
    assert!(!heard.contains(&firmware_protocol::Code::Identity), "{heard:?}");
}

/// Behind a slow adapter (every frame 20 ms late each way, as behind a USB-serial adapter's
/// latency timer) one poll of the 9 nodes takes over 300 ms (the CAN loss limit); nodes that
/// answer every poll are not lost for it, and the move completes.
#[test]
fn a_slow_serial_adapter_does_not_make_answering_nodes_lost() {
    let mut config = ServeConfig::new(reference(), PtyLink::SerialPty);
    config.faults = "delay=20ms".parse().unwrap();
    let (runtime, server) = start_with(config);
    let line = SerialLine::open(server.device_path()).unwrap();
    drive_over(&runtime, &server, line);
}

#[test]
fn an_emergency_stop_over_the_serial_pty_reaches_every_node() {
    let (_runtime, server) = start(PtyLink::SerialPty);
    let connection = Connection::open(&LinkSpec::Serial(server.device_path().into())).unwrap();
    dressform::form::controller::emergency_stop(&connection).unwrap();
    std::thread::sleep(Duration::from_millis(100));
    for node in server.form().state().nodes {
        assert!(node.faults.contains(Faults::EMERGENCY_STOP), "node {}", node.node.get());
    }
}

/// Unanswered exchanges while the link carries nothing are excused as a pty stall (up to
/// `LINK_STALL_LIMIT`); a truly silent node among answering ones is not: liveness reports it
/// after three polls, and a request to it fails after its attempts, each well before the
/// limit an excused node would take.
#[test]
fn a_silent_serial_node_is_reported_while_the_others_answer() {
    const ONSET: Duration = Duration::from_secs(2);
    let mut config = ServeConfig::new(reference(), PtyLink::SerialPty);
    config.faults = "node2:silent@2s".parse().unwrap();
    let (runtime, server) = start_with(config);
    let onset = std::time::Instant::now() + ONSET;
    let line = SerialLine::open(server.device_path()).unwrap();
    let mut session = Session::new(line, &reference());
    runtime.block_on(session.discover()).unwrap();
    assert!(std::time::Instant::now() < onset, "discovery took over {ONSET:?}");
    let lost =
        runtime.block_on(session.wait_until(Instant::now() + 2 * ONSET, |_| false)).unwrap_err();
    let noticed = onset.elapsed();
    assert!(matches!(lost, SessionError::NodeUnanswered { node: 2, .. }), "{lost}");
    assert!(noticed < LINK_STALL_LIMIT, "noticed {noticed:?} after the node fell silent");
    let asked = std::time::Instant::now();
    let refused = runtime.block_on(session.control(NodeId::new(2).unwrap(), DriveCommand::Enable));
    let waited = asked.elapsed();
    assert!(matches!(refused, Err(SessionError::NoAnswer { node: 2, .. })), "{refused:?}");
    assert!(waited < LINK_STALL_LIMIT, "no answer reported after {waited:?}");
}

#[test]
fn a_missing_device_is_a_clear_error() {
    let error = SerialLine::open(Path::new("/dev/does-not-exist")).unwrap_err();
    assert!(error.to_string().contains("/dev/does-not-exist"), "{error}");
}
