//! The bus load the in-process bus reports matches the budget table of
//! `firmware-protocol/README.md`: the frames and bus time of a full-form update, and the load
//! of 50 updates a second with the reference form's cyclic feedback, forces and heartbeats
//! (the test host announces this crate's protocol version, 1.1, so the nodes send it their
//! forces alongside their feedback).

use crate::test_host;

use firmware_protocol::message::Sync;
use firmware_protocol::update::{self, NodeTargets};
use firmware_protocol::{Code, Link, NodeId, PROTOCOL_VERSION, Position};
use form_description::reference;
use form_sim::bus::can::{CanBus, CanKind};
use form_sim::fault::FaultSpec;
use form_sim::robot::{SimOptions, SimulatedForm};
use test_host::TestHost;
use tokio::time::{Duration, Instant};

/// A row of the README's budget table.
struct Row {
    frames: u64,
    update_us: String,
    load_percent: f64,
}

/// The README's row for a link (by its name in the table).
fn readme_row(name: &str) -> Row {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../firmware-protocol/README.md");
    let readme = std::fs::read_to_string(path).unwrap();
    let line = readme
        .lines()
        .find(|l| l.starts_with(&format!("| {name} |")))
        .unwrap_or_else(|| panic!("no budget row for {name}"));
    let cells: Vec<&str> = line.split('|').map(str::trim).collect();
    Row {
        frames: cells[2].parse().unwrap(),
        update_us: cells[3].trim_end_matches(" µs").to_string(),
        load_percent: cells[5].trim_end_matches(" %").parse().unwrap(),
    }
}

const LINKS: [(&str, CanKind); 3] = [
    ("classic CAN, 1 Mbit/s", CanKind::CLASSIC_1M),
    ("CAN FD, 1 / 2 Mbit/s", CanKind::Fd { nominal: 1_000_000, data: 2_000_000 }),
    ("CAN FD, 1 / 5 Mbit/s", CanKind::FD_1M_5M),
];

/// A full update of the reference form: every actuator to `position`.
fn full_update(link: Link, position: Position) -> Vec<firmware_protocol::Packet> {
    let nodes: Vec<NodeTargets> = reference()
        .node_ids()
        .map(|node| NodeTargets { node, targets: [Some(position); 8] })
        .collect();
    update::packets(&nodes, Sync { duration_ms: 20 }, link).collect()
}

#[tokio::test(start_paused = true)]
async fn a_full_update_uses_the_frames_and_bus_time_of_the_readme() {
    for (name, kind) in LINKS {
        let row = readme_row(name);
        let bus = CanBus::new(kind);
        let host = TestHost::attach(&bus);
        for packet in full_update(kind.link(), Position::new(2500).unwrap()) {
            host.send(packet).await;
        }
        let stats = bus.stats();
        assert_eq!(stats.frames, row.frames, "{name}");
        let busy_us = format!("{:.1}", stats.busy.as_nanos() as f64 / 1000.0);
        assert_eq!(busy_us, row.update_us, "{name}");
    }
}

#[tokio::test(start_paused = true)]
async fn fifty_updates_a_second_with_cyclic_traffic_load_the_bus_as_the_readme_says() {
    for (name, kind) in LINKS {
        let row = readme_row(name);
        let description = reference();
        let bus = CanBus::new(kind);
        let _form = SimulatedForm::on_can(
            &description,
            &bus,
            &FaultSpec::default(),
            &SimOptions::default(),
        )
        .unwrap();
        let mut host = TestHost::attach(&bus);
        let nodes: Vec<NodeId> = description.node_ids().collect();
        host.enable_and_home(&nodes).await;
        // Every actuator is homed at 0: streaming 0 moves nothing and raises no event, so the
        // traffic is exactly the updates, the feedback and the heartbeats.
        let update = full_update(kind.link(), Position::ZERO);
        let before = bus.stats();
        let start = Instant::now();
        for i in 1..=100 {
            host.queue(update.iter().copied());
            host.run_until(start + Duration::from_millis(20 * i), |_| false).await;
        }
        let measured = bus.stats().since(&before);
        assert_eq!(measured.elapsed, Duration::from_secs(2));
        // The README's load counts one force frame per feedback frame (protocol 1.1: same
        // period, same shape); a mismatch here names the cause before the load does.
        let window = start..=start + measured.elapsed;
        let count = |codes: [Code; 3]| {
            host.received
                .iter()
                .filter(|(at, p)| window.contains(at) && codes.contains(&p.message.code()))
                .count()
        };
        let feedback = count([Code::FeedbackLower, Code::FeedbackUpper, Code::AllFeedback]);
        let forces = count([Code::ForceLower, Code::ForceUpper, Code::AllForce]);
        let expected = if PROTOCOL_VERSION.has_force() { feedback } else { 0 };
        assert!(feedback > 0, "{name}: no feedback");
        // A period's frames may straddle the end of the measurement.
        assert!(
            forces.abs_diff(expected) <= 2 * nodes.len(),
            "{name}: {forces} force frames for {feedback} feedback frames"
        );
        let load = 100.0 * measured.load();
        assert!(
            (load - row.load_percent).abs() < 0.3,
            "{name}: measured {load:.2} %, README {} %",
            row.load_percent
        );
        assert_eq!(measured.error_frames + measured.dropped + measured.overruns, 0);
    }
}
