//! Fault specs on the simulated reference form (in-process CAN, paused clock): node reboots,
//! silence and slow answers, jammed actuators and broken encoders, as a host sees them.

use crate::test_host;

use firmware_protocol::drive::{DriveState, EmergencyCode, Faults};
use firmware_protocol::message::{Positions8, Sync};
use firmware_protocol::{Address, Message, NodeId, Packet, Position};
use form_description::reference;
use form_sim::bus::can::{CanBus, CanKind};
use form_sim::fault::FaultSpec;
use form_sim::node::ActuatorFault;
use form_sim::robot::{SimOptions, SimulatedForm};
use test_host::{TestHost, last_heartbeat, node};
use tokio::time::{Duration, Instant};

/// The reference form with `faults`, enabled and homed (homing takes under 1.5 s, so
/// faults timed from 2 s on hit a ready form).
async fn ready_form(faults: &str) -> (CanBus, SimulatedForm, TestHost) {
    let faults: FaultSpec = faults.parse().unwrap();
    let description = reference();
    let bus = CanBus::with(CanKind::CLASSIC_1M, &faults, None);
    let form = SimulatedForm::on_can(&description, &bus, &faults, &SimOptions::default()).unwrap();
    let mut host = TestHost::attach(&bus);
    let nodes: Vec<NodeId> = description.node_ids().collect();
    host.enable_and_home(&nodes).await;
    assert!(Instant::now() - bus.origin() < Duration::from_millis(1500));
    host.clear();
    (bus, form, host)
}

fn from(packet: &Packet, id: u8) -> bool {
    packet.address == Address::Node(node(id))
}

#[tokio::test(start_paused = true)]
async fn a_rebooted_node_comes_back_disabled_and_unhomed() {
    let (bus, form, mut host) = ready_form("node3:reboot@2500ms").await;
    host.run_until(bus.origin() + Duration::from_secs(3), |_| false).await;
    let boot = host.received.iter().find(|(_, p)| {
        from(p, 3) && matches!(p.message, Message::Heartbeat(h) if h.state == DriveState::Disabled)
    });
    let (at, _) = boot.expect("no boot-up heartbeat from node 3");
    assert!(*at - bus.origin() >= Duration::from_millis(2500));
    let truth = form.state();
    assert_eq!(truth.node(node(3)).unwrap().state, DriveState::Disabled);
    assert!(truth.actuators.iter().filter(|a| a.node == node(3)).all(|a| !a.state.homed));
    assert_eq!(truth.node(node(4)).unwrap().state, DriveState::Enabled);
}

#[tokio::test(start_paused = true)]
async fn a_silent_node_says_nothing_and_its_watchdog_trips() {
    let (bus, form, mut host) = ready_form("node2:silent@2s..2500ms").await;
    let origin = bus.origin();
    host.run_until(origin + Duration::from_secs(3), |_| false).await;
    let window = origin + Duration::from_millis(2002)..origin + Duration::from_millis(2500);
    let during = host.received.iter().filter(|(at, p)| window.contains(at) && from(p, 2)).count();
    assert_eq!(during, 0, "node 2 spoke while silent");
    assert!(host.received.iter().any(|(at, p)| *at > window.end && from(p, 2)));
    // It heard no host heartbeat either: Fault, HOST_TIMEOUT.
    let node2 = *form.state().node(node(2)).unwrap();
    assert_eq!((node2.state, node2.faults), (DriveState::Fault, Faults::HOST_TIMEOUT));
    let heartbeat = last_heartbeat(&host.received, node(2)).unwrap();
    assert_eq!(heartbeat.faults, Faults::HOST_TIMEOUT);
}

#[tokio::test(start_paused = true)]
async fn a_slow_node_answers_late() {
    let (_bus, _form, mut host) = ready_form("node5:slow=40ms").await;
    host.send(Packet::broadcast(Message::IdentifyRequest)).await;
    let asked = Instant::now();
    host.run_for(Duration::from_millis(100)).await;
    let answered = |id| {
        host.received
            .iter()
            .find(|(_, p)| from(p, id) && matches!(p.message, Message::Identity(_)))
            .map(|(at, _)| *at - asked)
            .unwrap()
    };
    assert!(answered(4) < Duration::from_millis(5), "{:?}", answered(4));
    assert!(answered(5) >= Duration::from_millis(40), "{:?}", answered(5));
}

#[tokio::test(start_paused = true)]
async fn a_stalled_actuator_raises_a_following_error_during_a_move() {
    let (_bus, form, mut host) = ready_form("chest-l1:stall@1600ms").await;
    let targets = Positions8 { positions: [Position::new(3000); 8] };
    host.queue([
        Packet::node(
            node(2),
            Message::Targets(targets.half(firmware_protocol::message::Half::Lower)),
        ),
        Packet::node(
            node(2),
            Message::Targets(targets.half(firmware_protocol::message::Half::Upper)),
        ),
        Packet::broadcast(Message::Sync(Sync { duration_ms: 0 })),
    ]);
    host.run_for(Duration::from_secs(1)).await;
    let event = host.received.iter().find_map(|(_, p)| match p.message {
        Message::Emergency(e) if from(p, 2) => Some(e),
        _ => None,
    });
    let event = event.expect("no emergency from node 2");
    assert_eq!(event.code, EmergencyCode::FOLLOWING_ERROR);
    assert_eq!(event.actuator.map(|a| a.index()), Some(1));
    let truth = form.state();
    assert_eq!(truth.node(node(2)).unwrap().state, DriveState::Fault);
    let chest = truth.actuator("chest-l1").unwrap();
    assert!(chest.state.stalled && !chest.state.homed);
    // The other nodes carry on.
    assert!(truth.actuator("waist-l1").is_some_and(|a| a.state.homed));
}

#[tokio::test(start_paused = true)]
async fn a_broken_encoder_is_reported_at_once() {
    let (bus, form, mut host) = ready_form("thigh-r-back:encoder@2s").await;
    host.run_until(bus.origin() + Duration::from_millis(2100), |_| false).await;
    let event = host.received.iter().find_map(|(at, p)| match p.message {
        Message::Emergency(e) if from(p, 8) => Some((*at, e)),
        _ => None,
    });
    let (at, event) = event.expect("no emergency from node 8");
    // Within a tick, and the frames every node queued at 2 s before it (its port is a FIFO):
    // 9 nodes' heartbeat, two feedback and two force halves, 45 frames of 135 µs, 6.1 ms.
    assert!(at - bus.origin() < Duration::from_millis(2008), "{:?}", at - bus.origin());
    assert_eq!(
        (event.code, event.actuator.map(|a| a.index())),
        (EmergencyCode::FOLLOWING_ERROR, Some(4))
    );
    assert!(form.state().actuator("thigh-r-back").unwrap().state.encoder_fault);
}

#[test]
fn a_fault_spec_naming_what_the_form_lacks_is_refused() {
    let runtime = tokio::runtime::Builder::new_current_thread().enable_all().build().unwrap();
    runtime.block_on(async {
        let bus = CanBus::new(CanKind::CLASSIC_1M);
        let faults: FaultSpec = "sleeve-l1:stall@1s".parse().unwrap();
        let error =
            SimulatedForm::on_can(&reference(), &bus, &faults, &SimOptions::default()).unwrap_err();
        assert!(error.to_string().contains("no actuator `sleeve-l1`"), "{error}");
    });
}

#[tokio::test(start_paused = true)]
async fn faults_can_be_injected_while_the_form_runs() {
    let (_bus, form, mut host) = ready_form("").await;
    assert!(form.inject("hip-r2", ActuatorFault::Encoder));
    assert!(!form.inject("hip-r9", ActuatorFault::Stall));
    assert!(form.reboot(node(1)));
    assert!(!form.reboot(node(10)));
    host.run_for(Duration::from_millis(10)).await;
    let truth = form.state();
    assert_eq!(truth.node(node(6)).unwrap().faults, Faults::FOLLOWING_ERROR);
    assert_eq!(truth.node(node(1)).unwrap().state, DriveState::Disabled);
    let event = host.received.iter().find_map(|(_, p)| match p.message {
        Message::Emergency(e) if from(p, 6) => Some(e),
        _ => None,
    });
    assert_eq!(
        event.map(|e| (e.code, e.actuator.map(|a| a.index()))),
        Some((EmergencyCode::FOLLOWING_ERROR, Some(6)))
    );
}
