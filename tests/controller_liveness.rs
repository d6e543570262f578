//! Liveness that tells a node's silence from the link's, and what a fault leaves behind.
//!
//! * Under tokio's paused clock, on the in-process CAN bus (deterministic): every node quiet
//!   together is the link's stall, excused up to `LINK_STALL_LIMIT` however the nodes come
//!   back (one of them first: the race that made the others "lost"); longer, it is reported
//!   as a stalled link, not as a node lost; one node quiet while the others talk is lost, its
//!   silence outside the link's stalls counted.
//! * A fault during homing or during a move leaves no node Enabled: none latches a host
//!   timeout once the host is gone (in-process, and over both ptys).
//! * Real time, over real pseudo-terminals: `dressform sim` as a child process, stopped with
//!   SIGSTOP for 0.5 s and 1.5 s in the middle of a move (the drive finishes and no node holds
//!   a fault afterwards) and for 2.5 s (the drive fails: the link stalled). Tries per case and
//!   link: `DRESSFORM_STALL_TRIES` (default 2; `tests/scripts/stress-test.sh` sets 20).

// Drives the simulated form (the `simulator` feature).
#![cfg(feature = "simulator")]

use std::collections::BTreeMap;
use std::io::{BufRead, BufReader};
use std::path::PathBuf;
use std::process::{Child, ChildStdout, Command, Stdio};
use std::sync::mpsc;
use std::time::Duration;

use dressform::form::controller::session::{
    LINK_STALL_LIMIT, NODE_LOST_AFTER, Session, SessionError,
};
use dressform::form::controller::transport::sim::SimBus;
use dressform::form::controller::{Connection, DriveError, DriveOptions, LinkSpec, drive, status};
use dressform::form::setpoints::SetPoints;
use firmware_protocol::drive::{DriveState, Faults};
use form_description::reference;
use form_sim::bus::can::{CanBus, CanKind};
use form_sim::fault::FaultSpec;
use form_sim::robot::{FormState, SimOptions, SimulatedForm};
use form_sim::serve::{PtyLink, ServeConfig, serve};
use tokio::time::Instant;

/// The reference form on an in-process classic CAN bus with `faults`, a session with it
/// whose discovery is done (liveness watched from then on), and when the bus started (the
/// faults' times count from there).
async fn discovered(faults: &str) -> (Rig, Session<SimBus>, Instant) {
    let faults: FaultSpec = faults.parse().unwrap();
    let origin = Instant::now();
    let bus = CanBus::with(CanKind::CLASSIC_1M, &faults, None);
    let form = SimulatedForm::on_can(&reference(), &bus, &faults, &SimOptions::default()).unwrap();
    let mut session = Session::new(SimBus::attach(&bus), &reference());
    session.discover().await.unwrap();
    assert!(origin.elapsed() < STALL_FROM, "discovery took {:?}", origin.elapsed());
    (Rig { form, _bus: bus }, session, origin)
}

/// A simulated form and its bus, alive together (the nodes stop before the bus).
struct Rig {
    form: SimulatedForm,
    _bus: CanBus,
}

/// Every node cut off from `from` for `stall`, node 5 coming back 20 ms before the others
/// (one feedback period: the first packet after the stall is node 5's).
fn every_node_silent(from: Duration, stall: Duration) -> String {
    let others = stall + Duration::from_millis(20);
    let nodes = reference().nodes.iter().map(|n| n.address).collect::<Vec<_>>();
    nodes
        .into_iter()
        .map(|n| {
            let to = from + if n == 5 { stall } else { others };
            format!("node{n}:silent@{}ms..{}ms", from.as_millis(), to.as_millis())
        })
        .collect::<Vec<_>>()
        .join(",")
}

/// When the link goes quiet in the paused-clock tests: discovery is long done (it takes
/// tens of simulated ms).
const STALL_FROM: Duration = Duration::from_secs(1);

/// The whole link quiet for 0.5 s and for 1.5 s, one node heard again before the others: no
/// node is lost (the first node heard used to make the others' silence count in full).
#[tokio::test(start_paused = true)]
async fn every_node_quiet_together_is_the_links_stall_and_no_node_is_lost() {
    for stall in [Duration::from_millis(500), Duration::from_millis(1500)] {
        let (form, mut session, origin) = discovered(&every_node_silent(STALL_FROM, stall)).await;
        let end = origin + STALL_FROM + stall + Duration::from_secs(1);
        let watched = session.wait_until(end, |_| false).await;
        assert!(matches!(watched, Ok(false)), "stall of {stall:?}: {watched:?}");
        assert!(form.form.state().nodes.iter().all(|n| !n.silent));
    }
}

/// The whole link quiet for longer than `LINK_STALL_LIMIT` is reported as the link's stall,
/// as soon as it passes the limit, not as a node lost.
#[tokio::test(start_paused = true)]
async fn a_stall_past_the_limit_is_the_link_stalled_not_a_node_lost() {
    let stall = Duration::from_millis(2500);
    let (_form, mut session, origin) = discovered(&every_node_silent(STALL_FROM, stall)).await;
    let error = session.wait_until(origin + 2 * stall, |_| false).await.unwrap_err();
    let noticed = origin.elapsed();
    let text = error.to_string();
    let SessionError::LinkStalled { quiet } = error else { panic!("{text}") };
    assert!(
        quiet > LINK_STALL_LIMIT && quiet < LINK_STALL_LIMIT + Duration::from_millis(30),
        "{quiet:?}"
    );
    assert!(text.starts_with("the link carried nothing from any node for 2.0 s (limit 2 s)"));
    assert!(!text.contains(": lost:"), "{text}");
    // Noticed while the link was still quiet, once the limit had passed since the last
    // packet (at most one feedback period, 20 ms, before the nodes fell silent).
    let earliest = STALL_FROM + LINK_STALL_LIMIT - Duration::from_millis(20);
    assert!(noticed > earliest && noticed < STALL_FROM + stall, "{noticed:?}");
}

/// A stall past the limit that ends while the session is busy with a request (which waits
/// out the link's stalls) is still reported once it looks, as the link's stall.
#[tokio::test(start_paused = true)]
async fn a_stall_past_the_limit_that_ended_during_a_request_is_still_the_links() {
    let stall = Duration::from_millis(2050);
    let (_form, mut session, origin) = discovered(&every_node_silent(STALL_FROM, stall)).await;
    let until = origin + STALL_FROM + Duration::from_millis(100);
    assert!(matches!(session.wait_until(until, |_| false).await, Ok(false)));
    // Disabled already: the node acknowledges once it hears again.
    let node = firmware_protocol::NodeId::new(1).unwrap();
    session.control(node, firmware_protocol::drive::DriveCommand::Disable).await.unwrap();
    assert!(origin.elapsed() > STALL_FROM + stall, "{:?}", origin.elapsed());
    let error = session.wait_until(Instant::now() + stall, |_| false).await.unwrap_err();
    assert!(matches!(error, SessionError::LinkStalled { quiet } if quiet > LINK_STALL_LIMIT));
}

/// One node silent from 1 s; the whole link quiet from 1.2 s to 1.7 s: the node's 200 ms of
/// silence before the stall and what follows the stall count, the stall does not — it is
/// lost 0.3 s of its own silence later, at about 1.8 s.
#[tokio::test(start_paused = true)]
async fn a_silent_node_is_lost_on_its_own_silence_the_links_stall_left_out() {
    let faults = format!(
        "node2:silent@1s,{}",
        reference()
            .nodes
            .iter()
            .map(|n| n.address)
            .filter(|&n| n != 2)
            .map(|n| format!("node{n}:silent@1200ms..1700ms"))
            .collect::<Vec<_>>()
            .join(",")
    );
    let (_form, mut session, origin) = discovered(&faults).await;
    let error = session.wait_until(origin + Duration::from_secs(4), |_| false).await.unwrap_err();
    let noticed = origin.elapsed();
    let SessionError::NodeLost { node: 2, silent } = error else { panic!("{error}") };
    assert!(silent > NODE_LOST_AFTER && silent <= Duration::from_millis(320), "{silent:?}");
    let expected = Duration::from_millis(1800);
    assert!(
        noticed >= expected - Duration::from_millis(40)
            && noticed <= expected + Duration::from_millis(40),
        "noticed at {noticed:?}"
    );
}

/// A few actuators on several nodes, all at `mm`.
fn setpoints(mm: f64) -> SetPoints {
    let positions: BTreeMap<String, f64> = ["chest-l1", "chest-r1", "waist-front", "hip-back"]
        .into_iter()
        .map(|id| (id.to_string(), mm))
        .collect();
    SetPoints::new("reference", positions)
}

/// No node is left Enabled or Homing, none latched a host timeout; the faulty node 2 holds
/// its following error.
fn nothing_left_enabled(truth: &FormState) {
    for node in &truth.nodes {
        assert!(
            !matches!(node.state, DriveState::Enabled | DriveState::Homing),
            "node {} left {:?}: {:?}",
            node.node.get(),
            node.state,
            truth.nodes
        );
        assert!(!node.faults.contains(Faults::HOST_TIMEOUT), "{:?}", truth.nodes);
    }
    let chest = truth.nodes.iter().find(|n| n.node.get() == 2).unwrap();
    assert!(chest.faults.contains(Faults::FOLLOWING_ERROR), "{:?}", truth.nodes);
}

/// A jam during homing (from the start) and one during the move (homing and discovery take
/// about 1.2 s; the move is under way at 2 s): the drive fails naming the fault, and a second
/// after it ended no node is Enabled and none latched a host timeout (every node but the
/// faulty one used to stay Enabled and time out once the host had gone).
#[tokio::test(start_paused = true)]
async fn a_fault_during_homing_or_a_move_leaves_no_node_enabled() {
    for faults in ["chest-l1:stall@0s", "chest-l1:stall@2s"] {
        let faults: FaultSpec = faults.parse().unwrap();
        let bus = CanBus::with(CanKind::CLASSIC_1M, &faults, None);
        let form =
            SimulatedForm::on_can(&reference(), &bus, &faults, &SimOptions::default()).unwrap();
        let options = DriveOptions { min_duration: Duration::from_secs(4), ..Default::default() };
        let error = drive(SimBus::attach(&bus), &reference(), &setpoints(30.0), &options, |_| {})
            .await
            .unwrap_err();
        assert!(
            matches!(error, DriveError::Session(SessionError::Fault(ref f)) if f.node.address == 2),
            "{faults}: {error}"
        );
        tokio::time::sleep(Duration::from_secs(1)).await;
        nothing_left_enabled(&form.state());
    }
}

/// The same over both ptys, in real time: a jam during homing leaves no node Enabled.
#[test]
fn a_fault_during_homing_over_a_pty_leaves_no_node_enabled() {
    for transport in [PtyLink::SerialPty, PtyLink::SlcanPty] {
        let runtime = tokio::runtime::Builder::new_current_thread().enable_all().build().unwrap();
        let mut config = ServeConfig::new(reference(), transport);
        config.faults = "chest-l1:stall@0s".parse().unwrap();
        let server = serve(config).unwrap();
        let path = server.device_path().to_path_buf();
        let spec = match transport {
            PtyLink::SerialPty => LinkSpec::Serial(path),
            PtyLink::SlcanPty => LinkSpec::Slcan(path),
        };
        let connection = Connection::open(&spec).unwrap();
        let options = DriveOptions::default();
        let error = runtime
            .block_on(drive(connection, &reference(), &setpoints(30.0), &options, |_| {}))
            .unwrap_err();
        assert!(error.to_string().contains("fault on node 2 (chest)"), "{transport:?}: {error}");
        std::thread::sleep(Duration::from_secs(1));
        nothing_left_enabled(&server.form().state());
    }
}

/// How many tries per stall and link the real-time stall test makes.
fn tries() -> usize {
    std::env::var("DRESSFORM_STALL_TRIES").ok().and_then(|t| t.parse().ok()).unwrap_or(2)
}

/// How long into the move the simulator is stopped (progress comes every 50 ms).
const STOP_AT: Duration = Duration::from_millis(300);
/// How long the moves last: the longest stop excused (1.5 s) ends well before, on a loaded
/// machine too.
const MOVE: Duration = Duration::from_secs(3);
/// How long a drive may take to start moving: the first homes every node (up to 12 s at
/// the nodes' homing speed), and a loaded machine is slow.
const START_TIMEOUT: Duration = Duration::from_secs(60);

/// `dressform sim` as a child process, serving the reference form on a pty.
struct SimProcess {
    child: Child,
    path: PathBuf,
    // Kept open: the simulator's standard output.
    _stdout: BufReader<ChildStdout>,
}

impl SimProcess {
    fn start(flag: &str) -> Self {
        let mut child = Command::new(env!("CARGO_BIN_EXE_dressform"))
            .args(["sim", flag])
            .stdout(Stdio::piped())
            .stderr(Stdio::null())
            .spawn()
            .expect("dressform sim starts");
        let mut stdout = BufReader::new(child.stdout.take().expect("stdout"));
        let mut line = String::new();
        stdout.read_line(&mut line).expect("the pty's path");
        let path = PathBuf::from(line.trim());
        assert!(path.starts_with("/dev/"), "{line:?}");
        Self { child, path, _stdout: stdout }
    }

    fn signal(&self, signal: libc::c_int) {
        let pid = libc::pid_t::try_from(self.child.id()).unwrap();
        // SAFETY: kill has no memory effects; `pid` is our child, not yet reaped.
        assert_eq!(unsafe { libc::kill(pid, signal) }, 0);
    }
}

impl Drop for SimProcess {
    fn drop(&mut self) {
        self.signal(libc::SIGCONT);
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// One drive to `mm` over `spec`, the simulator stopped for `stop` from [`STOP_AT`] into
/// the move: the drive's outcome (`Ok` or the error in words), and how long the simulator
/// really was stopped.
fn drive_through_a_stop(
    sim: &SimProcess,
    spec: &LinkSpec,
    stop: Duration,
    mm: f64,
) -> (Result<(), String>, Duration) {
    let (moving, started) = mpsc::channel();
    let spec = spec.clone();
    let driver = std::thread::spawn(move || {
        let runtime = tokio::runtime::Builder::new_current_thread().enable_all().build().unwrap();
        let connection = Connection::open(&spec).map_err(|e| e.to_string())?;
        let options = DriveOptions { min_duration: MOVE, ..Default::default() };
        let mut told = false;
        let progress = |p: &dressform::form::controller::Progress| {
            if !told && p.elapsed >= STOP_AT {
                told = true;
                let _ = moving.send(());
            }
        };
        let report = runtime
            .block_on(drive(connection, &reference(), &setpoints(mm), &options, progress))
            .map_err(|e| e.to_string())?;
        if report.converged() { Ok(()) } else { Err(format!("not converged: {report:?}")) }
    });
    if started.recv_timeout(START_TIMEOUT).is_err() {
        let outcome = driver.join().unwrap();
        return (Err(format!("never {STOP_AT:?} into the move: {outcome:?}")), Duration::ZERO);
    }
    let stopped = std::time::Instant::now();
    sim.signal(libc::SIGSTOP);
    std::thread::sleep(stop);
    sim.signal(libc::SIGCONT);
    let stopped = stopped.elapsed();
    (driver.join().unwrap(), stopped)
}

/// Every node answers, Disabled, no fault latched.
fn no_fault_latched(spec: &LinkSpec) -> Result<(), String> {
    let runtime = tokio::runtime::Builder::new_current_thread().enable_all().build().unwrap();
    let connection = Connection::open(spec).map_err(|e| e.to_string())?;
    let nodes = runtime
        .block_on(status(connection, &reference(), Duration::from_millis(200)))
        .map_err(|e| e.to_string())?;
    match nodes.iter().find(|n| n.state.as_deref() != Some("Disabled") || !n.faults.is_empty()) {
        Some(node) => Err(format!("after the drive: {node:?}")),
        None => Ok(()),
    }
}

/// The simulated form stopped with SIGSTOP mid-move, [`tries`] times per stop: 0.5 s and
/// 1.5 s are the link's stalls (the drive finishes, no node lost, no node latched a host
/// timeout once the simulator went on); 2.5 s is past `LINK_STALL_LIMIT` and reported as
/// the link's stall, never as a node lost.
fn stopped_simulator(flag: &str, link: fn(PathBuf) -> LinkSpec) {
    let sim = SimProcess::start(flag);
    let spec = link(sim.path.clone());
    let mut failures = Vec::new();
    let mut drives = 0;
    for run in 1..=tries() {
        for stop in [500, 1500, 2500].map(Duration::from_millis) {
            drives += 1;
            let mm = if drives % 2 == 0 { 4.0 } else { 8.0 };
            let (outcome, stopped) = drive_through_a_stop(&sim, &spec, stop, mm);
            eprintln!("{flag} try {run}, stop {stop:?} (really {stopped:?}): {outcome:?}");
            let outcome = if stop < LINK_STALL_LIMIT {
                outcome.and_then(|()| no_fault_latched(&spec))
            } else {
                match outcome {
                    Err(e) if e.starts_with("the link carried nothing from any node") => Ok(()),
                    Err(e) => Err(e),
                    Ok(()) => Err("the drive went through a stall past the limit".into()),
                }
            };
            if let Err(e) = outcome {
                failures.push(format!("try {run}, stop {stop:?} (really {stopped:?}): {e}"));
            }
            if stop >= LINK_STALL_LIMIT {
                // The nodes were Enabled when the host gave up: they latch a host timeout
                // once the simulator goes on, which the next drive clears.
                std::thread::sleep(Duration::from_millis(500));
            }
        }
    }
    let list = failures.join("\n");
    assert!(failures.is_empty(), "{flag}: {} of {drives} drives failed:\n{list}", failures.len());
}

#[test]
fn a_stopped_simulator_is_the_links_stall_over_serial() {
    stopped_simulator("--serial-pty", LinkSpec::Serial);
}

#[test]
fn a_stopped_simulator_is_the_links_stall_over_slcan() {
    stopped_simulator("--slcan-pty", LinkSpec::Slcan);
}
