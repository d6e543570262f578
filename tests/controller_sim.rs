//! The controller against the simulated reference form on the in-process CAN bus, under
//! tokio's paused clock (deterministic, a few simulated seconds each): full-form moves on
//! classic CAN and CAN FD, lossy buses, reboots, silent nodes, faults, emergency stops and
//! discovery errors.

// Drives the simulated form (the `simulator` feature).
#![cfg(feature = "simulator")]

use std::collections::BTreeMap;
use std::time::Duration;

use dressform::form::controller::simulated::{SimConfig, SimDriveError, drive_on_sim};
use dressform::form::controller::transport::sim::SimBus;
use dressform::form::controller::{
    DriveError, DriveOptions, MoveError, NodeProblem, SessionError, StopCause, Transport,
    emergency_stop,
};
use dressform::form::setpoints::SetPoints;
use firmware_protocol::drive::{DriveState, Faults};
use form_description::{FormDescription, reference};
use form_sim::bus::can::{CanBus, CanKind};
use form_sim::fault::FaultSpec;
use form_sim::robot::{SimOptions, SimulatedForm};
use tokio::time::Instant;

/// Every actuator and lift of `form` somewhere in its stroke (a different place each).
fn full_form_setpoints(form: &FormDescription) -> SetPoints {
    let positions: BTreeMap<String, f64> = form
        .axes()
        .enumerate()
        .map(|(i, a)| {
            (a.id.to_string(), (a.stroke_mm * (0.2 + 0.1 * (i % 7) as f64) * 100.0).round() / 100.0)
        })
        .collect();
    SetPoints::new(form.name.clone(), positions)
}

fn config(kind: CanKind, faults: &str) -> SimConfig {
    SimConfig { kind, faults: faults.parse().unwrap(), ..SimConfig::default() }
}

/// Both built-in forms (the reference and the male one), every panel actuator and lift moved.
#[tokio::test(start_paused = true)]
async fn a_full_form_update_converges_on_classic_can_and_fd() {
    for (name, _) in form_description::BUILTIN {
        full_form_update_converges(&form_description::builtin(name).unwrap()).await;
    }
}

async fn full_form_update_converges(form: &FormDescription) {
    let setpoints = full_form_setpoints(form);
    let count = form.axes().count();
    for kind in [CanKind::CLASSIC_1M, CanKind::FD_1M_5M] {
        let (report, truth) =
            drive_on_sim(form, &setpoints, &DriveOptions::default(), &config(kind, ""), |_| {})
                .await
                .unwrap();
        assert_eq!(report.actuators.len(), count, "{}", form.name);
        assert!(report.converged(), "{report:?}");
        for a in &report.actuators {
            let real = truth.actuator(&a.id).unwrap().state.position_mm;
            assert!((real - a.target_mm).abs() <= 0.1, "{}: {real} vs {}", a.id, a.target_mm);
            assert!(a.error_mm.unwrap().abs() <= 0.1);
        }
        // All arrive together: at most one feedback period (+ the check's granularity) apart.
        let settled: Vec<u64> = report.actuators.iter().filter_map(|a| a.settled_ms).collect();
        assert_eq!(settled.len(), count);
        assert!(report.warnings.is_empty(), "{:?}", report.warnings);
        // The move lasts the shortest common duration: the longest distance at the limits.
        assert!(report.duration_ms > 0 && report.duration_ms < 10_000, "{}", report.duration_ms);
        // Left disabled, panels held.
        assert!(truth.nodes.iter().all(|n| n.state == DriveState::Disabled), "{:?}", truth.nodes);
    }
}

#[tokio::test(start_paused = true)]
async fn a_lossy_bus_still_converges() {
    let form = reference();
    let setpoints = full_form_setpoints(&form);
    for seed in 0..6 {
        let kind = if seed % 2 == 0 { CanKind::CLASSIC_1M } else { CanKind::FD_1M_5M };
        let config = config(kind, &format!("drop=0.05,corrupt=0.01,seed={seed}"));
        let (report, truth) =
            drive_on_sim(&form, &setpoints, &DriveOptions::default(), &config, |_| {})
                .await
                .unwrap_or_else(|e| panic!("seed {seed}: {e}"));
        assert!(report.converged(), "{report:?}");
        for a in &report.actuators {
            let real = truth.actuator(&a.id).unwrap().state.position_mm;
            assert!((real - a.target_mm).abs() <= 0.1, "seed {seed}, {}: {real}", a.id);
        }
    }
}

#[tokio::test(start_paused = true)]
async fn a_node_rebooting_mid_move_is_reidentified_and_the_move_resumes() {
    let form = reference();
    let setpoints = full_form_setpoints(&form);
    // Discovery and homing take about 1.2 s; the move is under way at 2 s.
    let config = config(CanKind::CLASSIC_1M, "node3:reboot@2s");
    let (report, truth) =
        drive_on_sim(&form, &setpoints, &DriveOptions::default(), &config, |_| {}).await.unwrap();
    assert!(report.converged(), "{report:?}");
    assert!(report.warnings.iter().any(|w| w.contains("node 3 rebooted")), "{:?}", report.warnings);
    for a in &report.actuators {
        let real = truth.actuator(&a.id).unwrap().state.position_mm;
        assert!((real - a.target_mm).abs() <= 0.1, "{}: {real} vs {}", a.id, a.target_mm);
    }
}

#[tokio::test(start_paused = true)]
async fn repeated_reboots_end_in_a_clear_failure() {
    let form = reference();
    let setpoints = full_form_setpoints(&form);
    let config = config(CanKind::CLASSIC_1M, "node3:reboot@2s,node3:reboot@3.5s,node3:reboot@5s");
    let error = drive_on_sim(&form, &setpoints, &DriveOptions::default(), &config, |_| {})
        .await
        .unwrap_err();
    assert!(
        matches!(
            error,
            SimDriveError::Drive(DriveError::Move(MoveError::Rebooted { node: 3, .. }))
        ),
        "{error}"
    );
}

#[tokio::test(start_paused = true)]
async fn a_silent_node_is_reported_within_three_heartbeat_periods() {
    let form = reference();
    let setpoints = full_form_setpoints(&form);
    let start = Instant::now();
    let config = config(CanKind::CLASSIC_1M, "node2:silent@2s");
    let error = drive_on_sim(&form, &setpoints, &DriveOptions::default(), &config, |_| {})
        .await
        .unwrap_err();
    let noticed = start.elapsed();
    let SimDriveError::Drive(DriveError::Session(SessionError::NodeLost { node: 2, silent })) =
        error
    else {
        panic!("{error}")
    };
    assert!(silent <= Duration::from_millis(320), "{silent:?}");
    assert!(noticed <= Duration::from_millis(2000 + 300 + 20), "{noticed:?}");
    assert!(noticed >= Duration::from_millis(2000), "{noticed:?}");
}

#[tokio::test(start_paused = true)]
async fn a_fault_stops_every_actuator_and_names_the_actuator() {
    let form = reference();
    let setpoints = full_form_setpoints(&form);
    let config = config(CanKind::CLASSIC_1M, "chest-l1:encoder@2s");
    let error = drive_on_sim(&form, &setpoints, &DriveOptions::default(), &config, |_| {})
        .await
        .unwrap_err();
    let text = error.to_string();
    let SimDriveError::Drive(DriveError::Session(SessionError::Fault(fault))) = error else {
        panic!("{text}")
    };
    assert_eq!((fault.node.address, fault.actuator.as_deref()), (2, Some("chest-l1")), "{text}");
    assert!(text.contains("following error of"), "{text}");
    assert!(!text.contains("Some(") && !text.contains("Faults("), "{text}");
}

#[tokio::test(start_paused = true)]
async fn a_stall_during_homing_is_reported_at_once_naming_the_actuator() {
    let form = reference();
    let setpoints = full_form_setpoints(&form);
    // Jammed from the start: homing lags 1 mm (FollowingErrorLimit) after 0.2 s at 5 mm/s.
    let config = config(CanKind::CLASSIC_1M, "chest-l1:stall@0s");
    let start = Instant::now();
    let error = drive_on_sim(&form, &setpoints, &DriveOptions::default(), &config, |_| {})
        .await
        .unwrap_err();
    let reported = start.elapsed();
    let text = error.to_string();
    let SimDriveError::Drive(DriveError::Session(SessionError::Fault(fault))) = error else {
        panic!("{text}")
    };
    assert_eq!(fault.actuator.as_deref(), Some("chest-l1"), "{text}");
    assert!(text.starts_with("fault on node 2 (chest), actuator chest-l1: following error"));
    // Discovery and enabling take a few hundred ms, the jam shows 0.2 s into homing: the
    // report follows within a second of the latch (the homing timeout is 30 s).
    assert!(reported < Duration::from_secs(1), "{reported:?}");
}

#[tokio::test(start_paused = true)]
async fn an_emergency_stop_reaches_every_node() {
    let form = reference();
    let bus = CanBus::new(CanKind::CLASSIC_1M);
    let simulated =
        SimulatedForm::on_can(&form, &bus, &FaultSpec::default(), &SimOptions::default()).unwrap();
    emergency_stop(&SimBus::attach(&bus)).unwrap();
    tokio::time::sleep(Duration::from_millis(10)).await;
    let truth = simulated.state();
    for node in &truth.nodes {
        assert_eq!(node.state, DriveState::Fault, "node {}", node.node.get());
        assert!(node.faults.contains(Faults::EMERGENCY_STOP));
    }
}

#[tokio::test(start_paused = true)]
async fn an_emergency_stop_from_another_thread_ends_the_move_and_nothing_follows_it() {
    let form = reference();
    let setpoints = full_form_setpoints(&form);
    let bus = CanBus::new(CanKind::CLASSIC_1M);
    let simulated =
        SimulatedForm::on_can(&form, &bus, &FaultSpec::default(), &SimOptions::default()).unwrap();
    let link = SimBus::attach(&bus);
    let gate = link.gate().clone();
    // Mid-move (discovery and homing take about 1.2 s), from a thread of its own as the
    // control endpoint and the signal thread do.
    tokio::spawn(async move {
        tokio::time::sleep(Duration::from_millis(2500)).await;
        std::thread::spawn(move || gate.emergency_stop(StopCause::Remote).unwrap()).join().unwrap();
    });
    let options = DriveOptions::default();
    let error = dressform::form::controller::drive(link, &form, &setpoints, &options, |_| {})
        .await
        .unwrap_err();
    assert!(
        matches!(error, DriveError::Session(SessionError::Stopped(StopCause::Remote))),
        "{error}"
    );
    assert!(error.to_string().contains("an e-stop from another terminal"), "{error}");
    // The nodes stay stopped: nothing (no FaultReset, no Enable) followed the stop.
    tokio::time::sleep(Duration::from_millis(1000)).await;
    let truth = simulated.state();
    assert!(truth.nodes.iter().all(|n| n.faults.contains(Faults::EMERGENCY_STOP)), "{truth:?}");
    assert!(truth.actuators.iter().all(|a| !a.state.moving), "{truth:?}");
}

#[tokio::test(start_paused = true)]
async fn nodes_that_differ_from_the_description_are_named() {
    let real = reference();
    let bus = CanBus::new(CanKind::CLASSIC_1M);
    let _simulated =
        SimulatedForm::on_can(&real, &bus, &FaultSpec::default(), &SimOptions::default()).unwrap();
    // The host's description: node 2's strokes differ, node 10 does not exist, node 8 is left
    // out (so it is unexpected).
    let mut described = real.clone().into_spec();
    for a in described.actuators.iter_mut().filter(|a| a.node == 2) {
        a.stroke_mm = 55.0;
    }
    for a in described.actuators.iter_mut().filter(|a| a.node == 8) {
        a.node = 10;
    }
    for n in described.nodes.iter_mut().filter(|n| n.address == 8) {
        n.address = 10;
    }
    let described = FormDescription::try_from(described).unwrap();
    let setpoints = SetPoints::new(real.name.clone(), BTreeMap::new());
    let error = dressform::form::controller::drive(
        SimBus::attach(&bus),
        &described,
        &setpoints,
        &DriveOptions::default(),
        |_| {},
    )
    .await
    .unwrap_err();
    let DriveError::Session(SessionError::Discovery(problems)) = &error else { panic!("{error}") };
    assert!(problems.contains(&NodeProblem::Missing(10)), "{error}");
    assert!(problems.contains(&NodeProblem::Unexpected(8)), "{error}");
    assert!(
        problems.iter().any(|p| matches!(p, NodeProblem::Mismatch { node: 2, what: "stroke", .. })),
        "{error}"
    );
}
