//! The simulated reference form on the in-process CAN bus, driven by a test host under
//! tokio's paused clock: the acceptance checks for motion, limits, the watchdog and
//! the emergency stop, and determinism.

use crate::test_host;

use std::collections::HashMap;

use firmware_protocol::drive::{DriveState, EmergencyCode, Faults};
use firmware_protocol::message::{Emergency, Sync};
use firmware_protocol::timing::FEEDBACK_PERIOD_MS;
use firmware_protocol::update::{self, NodeTargets};
use firmware_protocol::{Actuator, Address, Link, Message, NodeId, Packet, Position};
use form_description::{FormDescription, reference};
use form_sim::bus::can::{CanBus, CanKind};
use form_sim::fault::FaultSpec;
use form_sim::robot::{SimOptions, SimulatedForm};
use test_host::{TestHost, host_heartbeat};
use tokio::time::{Duration, Instant};

const TOLERANCE_MM: f64 = 0.1;

/// The reference form, enabled and homed, with a host.
async fn homed_form(kind: CanKind) -> (CanBus, SimulatedForm, TestHost, FormDescription) {
    let description = reference();
    let bus = CanBus::new(kind);
    let form =
        SimulatedForm::on_can(&description, &bus, &FaultSpec::default(), &SimOptions::default())
            .unwrap();
    let mut host = TestHost::attach(&bus);
    let nodes: Vec<NodeId> = description.node_ids().collect();
    host.enable_and_home(&nodes).await;
    host.clear();
    (bus, form, host, description)
}

/// A target for every actuator, the lifts' too, spread over 5..95 % of its stroke, in mm.
fn targets(description: &FormDescription) -> HashMap<String, f64> {
    description
        .axes()
        .enumerate()
        .map(|(i, a)| (a.id.to_string(), a.stroke_mm * (0.05 + 0.9 * ((i * 7) % 11) as f64 / 10.0)))
        .collect()
}

/// The update packets for `targets` from the current `positions` (mm), and the duration the
/// host picks: the largest shortest move.
fn full_update(
    description: &FormDescription,
    targets: &HashMap<String, f64>,
    positions: &HashMap<String, f64>,
    link: Link,
) -> (Vec<Packet>, u16) {
    let mut duration_ms = 0;
    let nodes: Vec<NodeTargets> = description
        .node_ids()
        .map(|n| {
            let mut node_targets = NodeTargets { node: n, targets: [None; 8] };
            for a in description.actuators_of(n) {
                let target = Position::from_mm(targets[a.id] as f32).unwrap();
                let from = Position::from_mm(positions[a.id] as f32).unwrap();
                let distance = target.hundredths_mm().abs_diff(from.hundredths_mm());
                let ms = update::shortest_duration_ms(distance, a.max_speed(), a.max_accel());
                duration_ms = duration_ms.max(ms.unwrap());
                node_targets.targets[usize::from(a.channel)] = Some(target);
            }
            node_targets
        })
        .collect();
    let duration_ms = u16::try_from(duration_ms).unwrap();
    let packets = update::packets(&nodes, Sync { duration_ms }, link).collect();
    (packets, duration_ms)
}

fn positions(form: &SimulatedForm) -> HashMap<String, f64> {
    form.state().actuators.into_iter().map(|a| (a.id, a.state.position_mm)).collect()
}

/// Polls every node every feedback period (the poll also feeds the watchdogs) until `until`.
async fn poll_until(host: &mut TestHost, nodes: &[NodeId], until: Instant) {
    host.heartbeats = false;
    while Instant::now() < until {
        host.queue(nodes.iter().map(|&n| Packet::node(n, host_heartbeat())));
        host.run_for(Duration::from_millis(u64::from(FEEDBACK_PERIOD_MS))).await;
    }
}

/// When each actuator (by node and index) was first reported at rest within the tolerance
/// of its target: a heartbeat saying it no longer moves, then feedback on target.
fn arrivals(
    received: &[(Instant, Packet)],
    description: &FormDescription,
    targets: &HashMap<String, f64>,
) -> HashMap<String, Instant> {
    let mut moving: HashMap<NodeId, u8> = HashMap::new();
    let mut arrived = HashMap::new();
    for (at, packet) in received {
        let Address::Node(n) = packet.address else { continue };
        let positions = match packet.message {
            Message::Heartbeat(h) => {
                moving.insert(n, h.moving.bits());
                continue;
            }
            Message::Feedback(four) => four.half.first()..four.half.first() + 4,
            _ => continue,
        };
        let Message::Feedback(four) = packet.message else { continue };
        for (index, slot) in positions.zip(four.positions) {
            let Some(spec) = description.actuator_at(n, Actuator::new(index as u8).unwrap()) else {
                continue;
            };
            let still = moving.get(&n).is_some_and(|m| m & (1 << index) == 0);
            let on_target = slot.is_some_and(|p| (p.mm() - targets[spec.id]).abs() <= TOLERANCE_MM);
            if still && on_target {
                arrived.entry(spec.id.to_string()).or_insert(*at);
            }
        }
    }
    arrived
}

#[tokio::test(start_paused = true)]
async fn a_synchronised_move_of_all_actuators_arrives_together_on_target() {
    let (_bus, form, mut host, description) = homed_form(CanKind::CLASSIC_1M).await;
    let nodes: Vec<NodeId> = description.node_ids().collect();
    let targets = targets(&description);
    let (packets, duration_ms) =
        full_update(&description, &targets, &positions(&form), Link::ClassicCan);
    assert_eq!(packets.len(), 19);
    assert!(duration_ms > 2000, "a full move takes seconds ({duration_ms} ms)");

    let start = Instant::now();
    host.queue(packets);
    // Sample the truth every millisecond: nobody exceeds its limits.
    let limits: HashMap<String, (f64, f64)> = description
        .axes()
        .map(|a| (a.id.to_string(), (a.max_speed_mm_s, a.max_accel_mm_s2)))
        .collect();
    let mut previous = form.state();
    let end = start + Duration::from_millis(u64::from(duration_ms) + 300);
    while Instant::now() < end {
        poll_until(&mut host, &nodes, Instant::now() + Duration::from_millis(20)).await;
        let state = form.state();
        let dt = (state.at - previous.at).as_secs_f64();
        for (now, before) in state.actuators.iter().zip(&previous.actuators) {
            let (speed, accel) = limits[&now.id];
            let v = now.state.velocity_mm_s;
            assert!(v.abs() <= speed + 1e-9, "{} at {v} mm/s", now.id);
            let a = (v - before.state.velocity_mm_s) / dt;
            assert!(a.abs() <= accel + 1e-6, "{} at {a} mm/s²", now.id);
        }
        previous = state;
    }

    let arrived = arrivals(&host.received, &description, &targets);
    assert_eq!(
        arrived.len(),
        description.axes().count(),
        "not every actuator arrived: {arrived:?}"
    );
    let first = arrived.values().min().unwrap();
    let last = arrived.values().max().unwrap();
    let spread = *last - *first;
    assert!(
        spread <= Duration::from_millis(u64::from(FEEDBACK_PERIOD_MS)),
        "arrivals spread over {spread:?}"
    );
    // They arrive when the SYNC said (it reached the nodes within the update's bus time).
    let planned = start + Duration::from_millis(u64::from(duration_ms));
    assert!(*first >= planned && *last <= planned + Duration::from_millis(25), "{first:?}");
    for actuator in form.state().actuators {
        let error = (actuator.state.position_mm - targets[&actuator.id]).abs();
        assert!(error <= TOLERANCE_MM, "{} is {error} mm off", actuator.id);
        assert!(!actuator.state.moving);
    }
}

#[tokio::test(start_paused = true)]
async fn the_same_move_on_can_fd_takes_ten_frames_and_arrives_on_target() {
    let (_bus, form, mut host, description) = homed_form(CanKind::FD_1M_5M).await;
    let targets = targets(&description);
    let (packets, duration_ms) =
        full_update(&description, &targets, &positions(&form), Link::CanFd);
    assert_eq!(packets.len(), 10);
    host.queue(packets);
    host.run_for(Duration::from_millis(u64::from(duration_ms) + 100)).await;
    for actuator in form.state().actuators {
        assert!((actuator.state.position_mm - targets[&actuator.id]).abs() <= TOLERANCE_MM);
    }
    // FD nodes send their positions in one AllFeedback frame.
    assert!(host.received.iter().any(|(_, p)| matches!(p.message, Message::AllFeedback(_))));
    assert!(!host.received.iter().any(|(_, p)| matches!(p.message, Message::Feedback(_))));
}

#[tokio::test(start_paused = true)]
async fn a_target_beyond_the_stroke_is_refused_with_a_fault_event_and_never_executed() {
    let (_bus, form, mut host, description) = homed_form(CanKind::CLASSIC_1M).await;
    let neck = description.actuator("neck-l1").unwrap();
    let (n, index) = description.locate("neck-l1").unwrap();
    let beyond = Position::from_mm((neck.stroke_mm + 5.0) as f32).unwrap();
    let mut node_targets = NodeTargets { node: n, targets: [None; 8] };
    node_targets.targets[index.index()] = Some(beyond);
    host.queue(update::packets(&[node_targets], Sync { duration_ms: 0 }, Link::ClassicCan));
    host.run_for(Duration::from_secs(3)).await;

    let refusal = Emergency {
        code: EmergencyCode::TARGET_OUT_OF_RANGE,
        actuator: Some(index),
        detail: i32::from(beyond.hundredths_mm()),
    };
    assert!(
        host.received.iter().any(|(_, p)| *p == Packet::node(n, Message::Emergency(refusal))),
        "no TargetOutOfRange event"
    );
    let truth = form.state();
    let actuator = truth.actuator("neck-l1").unwrap();
    assert_eq!(actuator.state.position_mm, 0.0, "the refused target moved the actuator");
    assert_eq!(actuator.state.staged, None);
    // A warning, not a fault: the node stays Enabled.
    assert_eq!(truth.node(n).unwrap().state, DriveState::Enabled);
}

#[tokio::test(start_paused = true)]
async fn the_watchdog_stops_motion_within_300_ms_and_one_tick_of_the_last_heartbeat() {
    let (_bus, form, mut host, description) = homed_form(CanKind::CLASSIC_1M).await;
    let targets = targets(&description);
    let (packets, _) = full_update(&description, &targets, &positions(&form), Link::ClassicCan);
    host.queue(packets);
    host.run_for(Duration::from_millis(1000)).await;
    assert!(form.state().actuators.iter().any(|a| a.state.velocity_mm_s.abs() > 1.0));

    // The last heartbeat: its end on the bus is when the nodes take it.
    host.heartbeats = false;
    host.send(Packet::broadcast(host_heartbeat())).await;
    let last_heartbeat = Instant::now();
    let tick = SimOptions::default().tick;
    let mut tripped = None;
    let mut braking: HashMap<String, f64> = HashMap::new();
    while Instant::now() < last_heartbeat + Duration::from_millis(700) {
        host.run_for(Duration::from_millis(1)).await;
        // Let the nodes' ticks of this instant run first.
        tokio::task::yield_now().await;
        let state = form.state();
        let all_fault = state.nodes.iter().all(|n| n.state == DriveState::Fault);
        if tripped.is_none() && state.nodes.iter().any(|n| n.state == DriveState::Fault) {
            assert!(all_fault, "every node trips at the same tick");
            tripped = Some(state.at);
        }
        if tripped.is_some() {
            for a in &state.actuators {
                let speed = a.state.velocity_mm_s.abs();
                let before = braking.insert(a.id.clone(), speed).unwrap_or(speed);
                assert!(speed <= before + 1e-9, "{} speeds up while stopping", a.id);
            }
        }
    }
    let tripped = tripped.expect("the watchdog never tripped");
    let after = tripped - last_heartbeat;
    assert!(
        after > Duration::from_millis(300) && after <= Duration::from_millis(300) + tick,
        "tripped {after:?} after the last heartbeat"
    );
    // Stopping at the acceleration limit takes at most max speed / max acceleration.
    let stop_by =
        description.axes().map(|a| a.max_speed_mm_s / a.max_accel_mm_s2).fold(0.0, f64::max);
    assert!(stop_by < 0.4);
    let state = form.state();
    assert!(state.actuators.iter().all(|a| a.state.velocity_mm_s == 0.0 && !a.state.moving));
    assert!(state.nodes.iter().all(|n| n.faults == Faults::HOST_TIMEOUT));
    let timeouts = host
        .received
        .iter()
        .filter(|(_, p)| {
            matches!(p.message, Message::Emergency(e) if e.code == EmergencyCode::HOST_TIMEOUT)
        })
        .count();
    assert_eq!(timeouts, description.nodes.len());
}

#[tokio::test(start_paused = true)]
async fn an_emergency_stop_halts_every_actuator() {
    let (_bus, form, mut host, description) = homed_form(CanKind::CLASSIC_1M).await;
    let targets = targets(&description);
    let (packets, _) = full_update(&description, &targets, &positions(&form), Link::ClassicCan);
    host.queue(packets);
    host.run_for(Duration::from_millis(800)).await;
    assert!(form.state().actuators.iter().all(|a| a.state.moving));

    host.send(Packet::broadcast(Message::EmergencyStop)).await;
    host.run_for(Duration::from_millis(500)).await;
    let stopped = form.state();
    assert!(
        stopped
            .nodes
            .iter()
            .all(|n| n.state == DriveState::Fault && n.faults == Faults::EMERGENCY_STOP)
    );
    assert!(stopped.actuators.iter().all(|a| a.state.velocity_mm_s == 0.0 && !a.state.moving));
    let events = host
        .received
        .iter()
        .filter(|(_, p)| {
            matches!(p.message, Message::Emergency(e) if e.code == EmergencyCode::EMERGENCY_STOP)
        })
        .count();
    assert_eq!(events, description.nodes.len());

    // Nothing moves any more, whatever the host sends.
    let (again, _) = full_update(&description, &targets, &positions(&form), Link::ClassicCan);
    host.queue(again);
    host.run_for(Duration::from_secs(2)).await;
    let later = form.state();
    for (a, b) in stopped.actuators.iter().zip(&later.actuators) {
        assert_eq!(a.state.position_mm, b.state.position_mm, "{} moved after the e-stop", a.id);
    }
}

/// Everything the host receives in a fixed scenario, relative to the bus's creation.
fn scenario() -> Vec<(Duration, Packet)> {
    let runtime = tokio::runtime::Builder::new_current_thread()
        .enable_all()
        .start_paused(true)
        .build()
        .unwrap();
    runtime.block_on(async {
        let (bus, form, mut host, description) = homed_form(CanKind::CLASSIC_1M).await;
        let targets = targets(&description);
        let (packets, _) = full_update(&description, &targets, &positions(&form), Link::ClassicCan);
        host.queue(packets);
        host.run_for(Duration::from_secs(2)).await;
        host.received.iter().map(|(at, p)| (*at - bus.origin(), *p)).collect()
    })
}

#[test]
fn runs_repeat_exactly_under_the_paused_clock() {
    let first = scenario();
    assert!(first.len() > 1000);
    assert_eq!(first, scenario());
}

#[tokio::test(start_paused = true)]
async fn a_sync_during_a_move_retargets_from_the_current_position_and_velocity() {
    let (_bus, form, mut host, description) = homed_form(CanKind::CLASSIC_1M).await;
    let targets = targets(&description);
    let (packets, _) = full_update(&description, &targets, &positions(&form), Link::ClassicCan);
    host.queue(packets);
    host.run_for(Duration::from_millis(1500)).await;
    // Back home as fast as possible, mid-move.
    let home: HashMap<String, f64> = targets.keys().map(|id| (id.clone(), 0.0)).collect();
    let (packets, _) = full_update(&description, &home, &positions(&form), Link::ClassicCan);
    let packets: Vec<Packet> = packets
        .into_iter()
        .map(|p| match p.message {
            Message::Sync(_) => Packet::broadcast(Message::Sync(Sync { duration_ms: 0 })),
            _ => p,
        })
        .collect();
    let before = form.state();
    host.queue(packets);
    let mut previous = before;
    for _ in 0..6000 {
        host.run_for(Duration::from_millis(1)).await;
        let state = form.state();
        let dt = (state.at - previous.at).as_secs_f64();
        for (a, b) in state.actuators.iter().zip(&previous.actuators) {
            let limit = description.axis(&a.id).unwrap().max_accel_mm_s2;
            let accel = (a.state.velocity_mm_s - b.state.velocity_mm_s) / dt;
            assert!(accel.abs() <= limit + 1e-6, "{} jerked: {accel}", a.id);
        }
        previous = state;
    }
    assert!(form.state().actuators.iter().all(|a| a.state.position_mm == 0.0));
    // No duration warning: duration 0 means as fast as the limits allow.
    assert!(!host.received.iter().any(|(_, p)| matches!(p.message, Message::Emergency(_))));
}
