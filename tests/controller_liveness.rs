//! Liveness that tells a node's silence from the link's, and what a fault leaves behind.
//!
//! * Under tokio's paused clock, on the in-process CAN bus (deterministic): every node quiet
//!   together is the link's stall, excused up to `LINK_STALL_LIMIT` however the nodes come
//!   back (one of them first: the race that made the others "lost"); longer, it is reported
//!   as a stalled link, not as a node lost; one node quiet while the others talk is lost, its
//!   silence outside the link's stalls counted.
//! * A fault during homing or during a move leaves no node Enabled: none latches a host
//!   timeout once the host is gone (in-process, and over both ptys).

use std::collections::BTreeMap;
use std::time::Duration;

use dressform::controller::session::{LINK_STALL_LIMIT, NODE_LOST_AFTER, Session, SessionError};
use dressform::controller::transport::sim::SimBus;
use dressform::controller::{Connection, DriveError, DriveOptions, LinkSpec, drive};
use dressform::setpoints::SetPoints;
use firmware_protocol::drive::{DriveState, Faults};
use form_description::reference;
use sim::bus::can::{CanBus, CanKind};
use sim::fault::FaultSpec;
use sim::robot::{FormState, SimOptions, SimulatedForm};
use sim::serve::{ServeConfig, Transport as Served, serve};
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
    (1..=8)
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
        (1..=8)
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
    for transport in [Served::SerialPty, Served::SlcanPty] {
        let runtime = tokio::runtime::Builder::new_current_thread().enable_all().build().unwrap();
        let mut config = ServeConfig::new(reference(), transport);
        config.faults = "chest-l1:stall@0s".parse().unwrap();
        let server = serve(config).unwrap();
        let path = server.device_path().to_path_buf();
        let spec = match transport {
            Served::SerialPty => LinkSpec::Serial(path),
            Served::SlcanPty => LinkSpec::Slcan(path),
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
