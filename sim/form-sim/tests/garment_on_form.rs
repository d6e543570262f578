//! A garment on the simulated reference form, on the in-process CAN bus under tokio's paused
//! clock: the forces the nodes report are the garment's load on the panels; a 1.0 host (one
//! that knows nothing of forces) drives the same form as before; a panel over its force limit
//! stalls.

use crate::test_host::{self, TestHost};

use std::collections::{BTreeMap, HashMap};

use firmware_protocol::drive::{DriveState, EmergencyCode, Faults};
use firmware_protocol::message::{Forces8, Sync};
use firmware_protocol::update::{self, NodeTargets};
use firmware_protocol::version::PROTOCOL_1_0;
use firmware_protocol::{Actuator, Address, Link, Message, NodeId, Packet, Position};
use form_description::garment::{GarmentSpec, shipped};
use form_description::{FormDescription, reference};
use form_sim::bus::can::{CanBus, CanKind};
use form_sim::fault::FaultSpec;
use form_sim::robot::{FORCE_NOISE_N, SimOptions, SimulatedForm, world};
use tokio::time::{Duration, Instant};

/// Every panel of the chest, under-bust and waist rings out by this much, mm: the jersey top
/// (relaxed 890 / 800 / 745 mm) is stretched on all three.
const OUT_MM: f64 = 40.0;

fn jersey(form: &FormDescription) -> GarmentSpec {
    GarmentSpec::from_toml_str(shipped("jersey-top").unwrap(), form).unwrap()
}

/// The reference form wearing `garment`, enabled and homed by a host announcing `protocol`.
async fn dressed_form(
    options: SimOptions,
    protocol: firmware_protocol::ProtocolVersion,
) -> (CanBus, SimulatedForm, TestHost, FormDescription) {
    let description = reference();
    let bus = CanBus::new(CanKind::CLASSIC_1M);
    let form = SimulatedForm::on_can(&description, &bus, &FaultSpec::default(), &options).unwrap();
    let mut host = TestHost::attach(&bus);
    host.protocol = protocol;
    let nodes: Vec<NodeId> = description.node_ids().collect();
    host.enable_and_home(&nodes).await;
    host.clear();
    (bus, form, host, description)
}

/// Moves the torso rings' panels out by [`OUT_MM`] (the rest stay home) in one SYNC of
/// `duration_ms` and runs the host until `until` after it.
async fn shape(
    host: &mut TestHost,
    description: &FormDescription,
    duration_ms: u16,
    run: Duration,
) {
    let rings = ["chest", "under-bust", "waist"];
    let nodes: Vec<NodeTargets> = description
        .node_ids()
        .map(|n| {
            let mut targets = NodeTargets { node: n, targets: [None; 8] };
            for a in description.actuators.iter().filter(|a| a.node == n.get()) {
                let out = if rings.contains(&a.ring.as_str()) { OUT_MM } else { 0.0 };
                targets.targets[usize::from(a.channel)] = Position::from_mm(out as f32);
            }
            targets
        })
        .collect();
    host.queue(update::packets(&nodes, Sync { duration_ms }, Link::ClassicCan));
    host.run_for(run).await;
}

/// The last forces each node reported, by actuator id, N.
fn reported(
    received: &[(Instant, Packet)],
    description: &FormDescription,
) -> BTreeMap<String, f64> {
    let mut by_node: HashMap<NodeId, Forces8> = HashMap::new();
    for (_, packet) in received {
        let (Address::Node(n), Message::Force(four)) = (packet.address, packet.message) else {
            continue;
        };
        by_node.entry(n).or_default().set_half(&four);
    }
    let mut forces = BTreeMap::new();
    for (n, all) in by_node {
        for (index, force) in all.forces.iter().enumerate() {
            if let (Some(axis), Some(f)) =
                (description.actuator_at(n, Actuator::new(index as u8).unwrap()), force)
            {
                forces.insert(axis.id.to_string(), f.n());
            }
        }
    }
    forces
}

/// With the jersey top on, the nodes report every panel's load as the garment model gives it
/// at the panels' true positions (within the sensors' 4σ noise and the wire's 0.01 N), and
/// the stretched rings' panels carry a few newtons.
#[tokio::test(start_paused = true)]
async fn the_nodes_report_the_garments_load_on_every_panel() {
    let options = SimOptions { garment: Some(jersey(&reference())), ..SimOptions::default() };
    let (_bus, form, mut host, description) =
        dressed_form(options, firmware_protocol::PROTOCOL_VERSION).await;
    shape(&mut host, &description, 4000, Duration::from_secs(6)).await;
    let truth: BTreeMap<String, f64> =
        form.state().actuators.into_iter().map(|a| (a.id, a.state.position_mm)).collect();
    let expected = world::loads(&description, &jersey(&description), &truth);
    let reported = reported(&host.received, &description);
    assert_eq!(reported.len(), description.axes().count(), "a force for every actuator");
    let limit = 4.0 * FORCE_NOISE_N + 0.005;
    for (id, force) in &reported {
        let want = expected.get(id).copied().unwrap_or(0.0);
        assert!((force - want).abs() <= limit, "{id}: reported {force} N, the model {want} N");
    }
    let waist: f64 =
        description.actuators.iter().filter(|a| a.ring == "waist").map(|a| expected[&a.id]).sum();
    assert!(waist > 5.0, "the stretched waist band presses: {waist} N");
}

/// A host of protocol 1.0 — one that decodes only 1.0's messages — drives the dressed 1.1
/// form as before: the nodes send it nothing of 1.1, and every panel arrives.
#[tokio::test(start_paused = true)]
async fn a_1_0_host_drives_1_1_nodes_as_before() {
    let options = SimOptions { garment: Some(jersey(&reference())), ..SimOptions::default() };
    let (_bus, form, mut host, description) = dressed_form(options, PROTOCOL_1_0).await;
    shape(&mut host, &description, 4000, Duration::from_secs(6)).await;
    let newer: Vec<_> =
        host.received.iter().filter(|(_, p)| p.message.code().since_minor() > 0).collect();
    assert!(newer.is_empty(), "a 1.0 host got 1.1 frames: {:?}", &newer[..newer.len().min(3)]);
    for a in form.state().actuators {
        let ring = description.actuator(&a.id).map(|s| s.ring.as_str());
        let want =
            if matches!(ring, Some("chest" | "under-bust" | "waist")) { OUT_MM } else { 0.0 };
        assert!((a.state.position_mm - want).abs() < 0.1, "{}: {}", a.id, a.state.position_mm);
    }
    let nodes: Vec<NodeId> = description.node_ids().collect();
    let heartbeats = host.last_heartbeats(&nodes).unwrap();
    assert!(heartbeats.iter().all(|h| h.state == DriveState::Enabled && h.faults.is_empty()));
}

/// The jersey top on actuators rated 5 N (it presses 0.2 N at home, 16 N at 40 mm out): the
/// first panel over its limit stops at once
/// and its node latches OVER_FORCE, naming it with the force; the form stops. Even a 1.0 host
/// sees the node in Fault (an unknown flag and code to it).
#[tokio::test(start_paused = true)]
async fn a_panel_over_its_force_limit_stalls_and_its_node_stops() {
    let description = reference();
    let options = SimOptions {
        garment: Some(jersey(&description)),
        rated_force_n: 5.0,
        ..SimOptions::default()
    };
    let (_bus, form, mut host, description) = dressed_form(options, PROTOCOL_1_0).await;
    shape(&mut host, &description, 4000, Duration::from_secs(6)).await;
    let events: Vec<_> = host
        .received
        .iter()
        .filter_map(|(_, p)| match (p.address, p.message) {
            (Address::Node(n), Message::Emergency(e)) if e.code == EmergencyCode::OVER_FORCE => {
                Some((n, e))
            }
            _ => None,
        })
        .collect();
    assert!(!events.is_empty(), "no OverForce event");
    let (node, event) = events[0];
    assert!(event.detail >= 500, "the force is at least the 5 N limit: {}", event.detail);
    let stalled = description.actuator_at(node, event.actuator.unwrap()).unwrap();
    let truth = form.state();
    let state = &truth.actuator(stalled.id).unwrap().state;
    assert!(state.position_mm > 0.5 && state.position_mm < OUT_MM - 0.5, "{state:?}");
    assert!(state.homed && !state.moving);
    let faulted = truth.node(node).unwrap();
    assert_eq!((faulted.state, faulted.faults), (DriveState::Fault, Faults::OVER_FORCE));
    let heartbeat = test_host::last_heartbeat(&host.received, node).unwrap();
    assert_eq!(heartbeat.state, DriveState::Fault);
}
