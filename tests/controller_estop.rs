//! The e-stop and recovery as a studio uses them, on real pseudo-terminals: the simulated
//! reference form served by `form_sim::serve` (serial mapping, or slcan as behind a USB-CAN
//! adapter), `dressform drive` moving it in one process, and `dressform estop` from another,
//! a SIGTERM, `dressform reset`, a jammed actuator. Real time: each case takes a few seconds;
//! waits are generous, for a loaded machine.

use std::path::Path;
use std::process::{Child, Command, Output, Stdio};
use std::time::{Duration, Instant};

use firmware_protocol::drive::{DriveState, Faults};
use form_sim::node::ActuatorFault;
use form_sim::serve::{PtyLink, Server};

use crate::controller_pty::start;

/// How long a drive may take to get moving (discovery and homing take about a second on a
/// quiet machine).
const START_TIMEOUT: Duration = Duration::from_secs(30);
/// How long the nodes may take to latch an e-stop; ~10 ms on a quiet machine (docs/performance.md
/// gives the measured latency), this much on a loaded one.
const LATCH_TIMEOUT: Duration = Duration::from_secs(5);

pub(crate) fn flag(transport: PtyLink) -> &'static str {
    match transport {
        PtyLink::SerialPty => "--serial",
        PtyLink::SlcanPty => "--slcan",
    }
}

/// A set-point file: long moves on two nodes (chest and waist), or short ones.
fn setpoints(dir: &Path, name: &str, mm: f64) -> String {
    let path = dir.join(name);
    let text = format!(
        r#"{{"format": "dressform-setpoints/1", "form": "reference",
            "positions_mm": {{"chest-l1": {mm}, "chest-r1": {mm}, "waist-front": {mm}}}}}"#
    );
    std::fs::write(&path, text).unwrap();
    path.display().to_string()
}

fn dressform(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_dressform")).args(args).output().expect("dressform runs")
}

pub(crate) fn text(output: &Output) -> String {
    format!(
        "status {:?}\nstdout:\n{}\nstderr:\n{}",
        output.status.code(),
        String::from_utf8_lossy(&output.stdout),
        String::from_utf8_lossy(&output.stderr)
    )
}

/// `dressform drive FILE --serial|--slcan PTY`, moving slowly, as a child process.
fn spawn_drive(server: &Server, transport: PtyLink, file: &str) -> Child {
    Command::new(env!("CARGO_BIN_EXE_dressform"))
        .args(["drive", file, flag(transport), server.device_path().to_str().unwrap()])
        .args(["--duration", "20"])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("dressform drive starts")
}

/// Waits until some panel of the simulated form moves.
fn wait_moving(server: &Server, child: &mut Child) {
    let deadline = Instant::now() + START_TIMEOUT;
    // Panels still braking from an earlier stop are not this drive's move.
    while server.form().state().actuators.iter().any(|a| a.state.moving) {
        std::thread::sleep(Duration::from_millis(2));
    }
    while !server.form().state().actuators.iter().any(|a| a.state.moving) {
        if let Some(status) = child.try_wait().unwrap() {
            panic!("drive ended before moving: {status}");
        }
        assert!(Instant::now() < deadline, "the form did not start moving");
        std::thread::sleep(Duration::from_millis(5));
    }
}

/// Waits until every node has latched the e-stop (and stopped).
fn wait_latched(server: &Server) {
    let deadline = Instant::now() + LATCH_TIMEOUT;
    loop {
        let truth = server.form().state();
        if truth.nodes.iter().all(|n| n.faults.contains(Faults::EMERGENCY_STOP)) {
            assert!(truth.nodes.iter().all(|n| n.state == DriveState::Fault), "{truth:?}");
            return;
        }
        assert!(Instant::now() < deadline, "not every node latched: {:?}", truth.nodes);
        std::thread::sleep(Duration::from_millis(1));
    }
}

/// A drive that works: exit 0 and the panels where the file says.
fn drive_works(server: &Server, transport: PtyLink, file: &str, extra: &[&str], mm: f64) {
    let device = server.device_path().to_str().unwrap();
    let mut args = vec!["drive", file, flag(transport), device];
    args.extend(extra);
    let out = dressform(&args);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out));
    let truth = server.form().state();
    for id in ["chest-l1", "chest-r1", "waist-front"] {
        let real = truth.actuator(id).unwrap().state.position_mm;
        assert!((real - mm).abs() <= 0.1, "{id}: {real} vs {mm}");
    }
}

/// While `drive` moves the form, `estop` from another process latches every node and the
/// drive exits 1 saying why; the next `drive` clears the e-stop and works; after an e-stop
/// sent directly (no owner), `reset` clears it and `drive` works.
fn estop_from_another_process(transport: PtyLink) {
    let (_runtime, server) = start(transport);
    let dir = tempfile::tempdir().unwrap();
    let device = server.device_path().to_str().unwrap().to_string();
    let far = setpoints(dir.path(), "far.json", 40.0);
    let mut drive = spawn_drive(&server, transport, &far);
    wait_moving(&server, &mut drive);
    let estop = dressform(&["estop", flag(transport), &device]);
    assert_eq!(estop.status.code(), Some(0), "{}", text(&estop));
    assert!(text(&estop).contains("which owns the link"), "{}", text(&estop));
    wait_latched(&server);
    let out = drive.wait_with_output().unwrap();
    assert_eq!(out.status.code(), Some(1), "{}", text(&out));
    assert!(text(&out).contains("stopped by an e-stop from another terminal"), "{}", text(&out));

    // The next drive clears the latched e-stop itself (and says so).
    let near = setpoints(dir.path(), "near.json", 3.0);
    drive_works(&server, transport, &near, &[], 3.0);

    // An e-stop with no owner goes over the link itself; `reset` clears it.
    let estop = dressform(&["estop", flag(transport), &device]);
    assert_eq!(estop.status.code(), Some(0), "{}", text(&estop));
    wait_latched(&server);
    let reset = dressform(&["reset", flag(transport), &device]);
    assert_eq!(reset.status.code(), Some(0), "{}", text(&reset));
    assert!(text(&reset).contains("node 2 (chest): emergency stop: cleared"), "{}", text(&reset));
    assert!(server.form().state().nodes.iter().all(|n| n.faults.is_empty()));
    let nearer = setpoints(dir.path(), "nearer.json", 2.0);
    drive_works(&server, transport, &nearer, &[], 2.0);
}

#[test]
fn estop_from_another_terminal_stops_a_serial_drive_and_the_form_recovers() {
    estop_from_another_process(PtyLink::SerialPty);
}

#[test]
fn estop_from_another_terminal_stops_an_slcan_drive_and_the_form_recovers() {
    estop_from_another_process(PtyLink::SlcanPty);
}

#[test]
fn sigterm_to_a_moving_drive_latches_the_estop_on_every_node() {
    for transport in [PtyLink::SerialPty, PtyLink::SlcanPty] {
        let (_runtime, server) = start(transport);
        let dir = tempfile::tempdir().unwrap();
        let far = setpoints(dir.path(), "far.json", 40.0);
        let mut drive = spawn_drive(&server, transport, &far);
        wait_moving(&server, &mut drive);
        let pid = libc::pid_t::try_from(drive.id()).unwrap();
        // SAFETY: kill has no memory effects; `pid` is our child, not yet reaped.
        assert_eq!(unsafe { libc::kill(pid, libc::SIGTERM) }, 0);
        wait_latched(&server);
        let out = drive.wait_with_output().unwrap();
        assert_eq!(out.status.code(), Some(1), "{}", text(&out));
        assert!(text(&out).contains("stopped by SIGTERM"), "{}", text(&out));
    }
}

/// A jam latches a following error; the next drive refuses to clear it on its own, naming
/// it; once the jam is freed, `--reset-faults` clears it and the drive works.
fn a_stall_needs_reset_faults(transport: PtyLink) {
    let (_runtime, server) = start(transport);
    let dir = tempfile::tempdir().unwrap();
    let near = setpoints(dir.path(), "near.json", 3.0);
    drive_works(&server, transport, &near, &[], 3.0);
    assert!(server.form().inject("chest-l1", ActuatorFault::Stall));
    let device = server.device_path().to_str().unwrap().to_string();
    let far = setpoints(dir.path(), "far.json", 6.0);
    let out = dressform(&["drive", &far, flag(transport), &device]);
    assert_eq!(out.status.code(), Some(1), "{}", text(&out));
    assert!(
        text(&out).contains("node 2 (chest), actuator chest-l1: following error"),
        "{}",
        text(&out)
    );

    let out = dressform(&["drive", &far, flag(transport), &device]);
    assert_eq!(out.status.code(), Some(1), "{}", text(&out));
    let refused = String::from_utf8_lossy(&out.stderr);
    assert!(refused.contains("node 2 (chest)") && refused.contains("following error"), "{refused}");
    assert!(refused.contains("--reset-faults"), "{refused}");
    for debug in ["Some(", "Faults(", "InvalidState"] {
        assert!(!refused.contains(debug), "{refused}");
    }
    assert!(server.form().state().nodes.iter().any(|n| n.faults.contains(Faults::FOLLOWING_ERROR)));

    assert!(server.form().repair("chest-l1"));
    drive_works(&server, transport, &far, &["--reset-faults"], 6.0);
}

#[test]
fn after_a_stall_drive_refuses_without_reset_faults_and_works_with_it_over_serial() {
    a_stall_needs_reset_faults(PtyLink::SerialPty);
}

#[test]
fn after_a_stall_drive_refuses_without_reset_faults_and_works_with_it_over_slcan() {
    a_stall_needs_reset_faults(PtyLink::SlcanPty);
}
