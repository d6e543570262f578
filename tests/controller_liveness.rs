//! Liveness that tells a node's silence from the link's, under tokio's paused clock on the
//! in-process CAN bus (deterministic): every node quiet together is the link's stall, excused
//! up to `LINK_STALL_LIMIT` however the nodes come back (one of them first: the race that made
//! the others "lost"); longer, it is reported as a stalled link, not as a node lost; one node
//! quiet while the others talk is lost, its silence outside the link's stalls counted.

use std::time::Duration;

use dressform::controller::session::{LINK_STALL_LIMIT, NODE_LOST_AFTER, Session, SessionError};
use dressform::controller::transport::sim::SimBus;
use form_description::reference;
use sim::bus::can::{CanBus, CanKind};
use sim::fault::FaultSpec;
use sim::robot::{SimOptions, SimulatedForm};
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
