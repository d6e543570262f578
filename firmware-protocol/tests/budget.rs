//! The bus budget of the README: a full-form update of the reference form (64 panel
//! actuators on 8 nodes and 8 lifts on a ninth) uses the fewest frames the README claims, and
//! the README's table is what the encoder and the timing formulas give, with the cyclic
//! traffic a node sends a host of this version (feedback, forces and heartbeats).

use std::path::Path;

use firmware_protocol::budget::Bus;
use firmware_protocol::message::Sync;
use firmware_protocol::timing::{
    FEEDBACK_PERIOD_MS, HEARTBEAT_PERIOD_MS, HOST_HEARTBEAT_PERIOD_MS,
};
use firmware_protocol::update::{self, NodeTargets};
use firmware_protocol::version::PROTOCOL_1_0;
use firmware_protocol::{
    Code, Link, NodeId, PROTOCOL_VERSION, Packet, Position, ProtocolVersion, can, serial,
};
use proptest::prelude::*;

const NODES: u8 = 9;
const ACTUATORS: usize = 8;
/// Set-point updates per second in the README's load column.
const UPDATE_HZ: u64 = 50;

const BUSES: [(&str, Bus); 4] = [
    ("classic CAN, 1 Mbit/s", Bus::ClassicCan { bitrate: 1_000_000 }),
    ("CAN FD, 1 / 2 Mbit/s", Bus::CanFd { nominal: 1_000_000, data: 2_000_000 }),
    ("CAN FD, 1 / 5 Mbit/s", Bus::CanFd { nominal: 1_000_000, data: 5_000_000 }),
    ("serial, 1 Mbaud 8N1", Bus::Serial { baud: 1_000_000 }),
];

fn reference_form() -> Vec<NodeTargets> {
    (1..=NODES)
        .map(|n| NodeTargets {
            node: NodeId::new(n).unwrap(),
            targets: [Position::new(2500); ACTUATORS],
        })
        .collect()
}

fn update(link: Link) -> Vec<Packet> {
    update::packets(&reference_form(), Sync { duration_ms: 2000 }, link).collect()
}

/// The fewest frames any encoding of the update can use: set-points name one node, so each
/// node needs ⌈its target bytes / the link's largest payload⌉ frames, plus the SYNC.
fn lower_bound(link: Link) -> usize {
    let largest_payload = match link {
        Link::ClassicCan => can::CLASSIC_MAX_LEN,
        Link::CanFd => can::FD_MAX_LEN,
        Link::Serial => serial::MAX_PAYLOAD,
    };
    usize::from(NODES) * (2 * ACTUATORS).div_ceil(largest_payload) + 1
}

#[test]
fn a_full_form_update_uses_the_fewest_frames_the_readme_claims() {
    for (link, claimed) in [(Link::ClassicCan, 19), (Link::CanFd, 10), (Link::Serial, 10)] {
        let packets = update(link);
        assert_eq!(packets.len(), claimed, "{link:?}");
        assert_eq!(packets.len(), lower_bound(link), "{link:?}");
        assert_eq!(packets.last().unwrap().message.code(), Code::Sync);
        // And every packet really goes out as one frame of that link.
        for p in &packets {
            let frame = can::encode(p).unwrap();
            assert_eq!(frame.is_fd(), link != Link::ClassicCan && p.message.code() != Code::Sync);
            assert!(serial::encode(&serial::Frame { seq: 0, packet: *p }).is_ok());
        }
    }
    // The README's serial byte count: 9 × 23 + 9.
    let serial_bytes: usize = update(Link::Serial)
        .into_iter()
        .map(|packet| serial::encode(&serial::Frame { seq: 0, packet }).unwrap().len())
        .sum();
    assert_eq!(serial_bytes, 216);
}

proptest! {
    #[test]
    fn partial_updates_send_only_halves_that_move(
        moves in proptest::collection::vec(proptest::array::uniform8(any::<bool>()), 1..=8)
    ) {
        let nodes: Vec<NodeTargets> = moves.iter().enumerate().map(|(i, m)| NodeTargets {
            node: NodeId::new(i as u8 + 1).unwrap(),
            targets: m.map(|moved| moved.then_some(Position::ZERO)),
        }).collect();
        let halves = moves.iter().flat_map(|m| m.chunks(4)).filter(|h| h.contains(&true)).count();
        let moving_nodes = moves.iter().filter(|m| m.contains(&true)).count();
        let sync = Sync { duration_ms: 100 };
        prop_assert_eq!(update::packets(&nodes, sync, Link::ClassicCan).count(), halves + 1);
        prop_assert_eq!(update::packets(&nodes, sync, Link::CanFd).count(), moving_nodes + 1);
    }
}

/// Bus time (ns) of packets on a bus.
fn time_ns(bus: Bus, packets: impl IntoIterator<Item = Packet>) -> u64 {
    packets.into_iter().map(|p| bus.frame_time_ns(p.message.code().payload_len())).sum()
}

/// Bus time (ns) per second of the cyclic traffic at the default periods, with a host of
/// protocol `host`: a node sends its forces (1.1) alongside its feedback, in the same period
/// and the same shape (two halves on classic CAN, one 16-byte frame on CAN FD and serial),
/// only to a host that announces force.
fn cyclic_ns_per_s(bus: Bus, host: ProtocolVersion) -> u64 {
    let per_s = |period_ms: u16| 1000 / u64::from(period_ms);
    let nodes = u64::from(NODES);
    let time = |code: Code| bus.frame_time_ns(code.payload_len());
    let mut per_feedback = match bus.link() {
        Link::ClassicCan => vec![Code::FeedbackLower, Code::FeedbackUpper],
        Link::CanFd => vec![Code::AllFeedback],
        // Each node is polled every feedback period: the poll and its answers.
        Link::Serial => vec![Code::HostHeartbeat, Code::Heartbeat, Code::AllFeedback],
    };
    if host.has_force() {
        per_feedback.extend(match bus.link() {
            Link::ClassicCan => vec![Code::ForceLower, Code::ForceUpper],
            Link::CanFd | Link::Serial => vec![Code::AllForce],
        });
    }
    let cyclic =
        nodes * per_s(FEEDBACK_PERIOD_MS) * per_feedback.into_iter().map(time).sum::<u64>();
    match bus.link() {
        Link::ClassicCan | Link::CanFd => {
            cyclic
                + nodes * per_s(HEARTBEAT_PERIOD_MS) * time(Code::Heartbeat)
                + per_s(HOST_HEARTBEAT_PERIOD_MS) * time(Code::HostHeartbeat)
        }
        Link::Serial => cyclic,
    }
}

#[test]
fn forces_load_the_bus_only_for_a_host_that_has_them() {
    for (name, bus) in BUSES {
        let (old, new) =
            (cyclic_ns_per_s(bus, PROTOCOL_1_0), cyclic_ns_per_s(bus, PROTOCOL_VERSION));
        // One more frame of the feedback's length per feedback frame (the serial poll and
        // heartbeat aside): AllForce and AllFeedback, ForceLower and FeedbackLower, ... are
        // each the same length.
        let feedback = match bus.link() {
            Link::ClassicCan => 2 * bus.frame_time_ns(Code::FeedbackLower.payload_len()),
            _ => bus.frame_time_ns(Code::AllFeedback.payload_len()),
        };
        let per_s = 1000 / u64::from(FEEDBACK_PERIOD_MS);
        assert_eq!(new - old, u64::from(NODES) * per_s * feedback, "{name}");
    }
}

fn budget_table() -> String {
    let mut table = String::from(
        "| link | frames per update | bus time per update | updates/s, bus otherwise idle | \
         load at 50 updates/s with feedback, forces and heartbeats |\n|---|--:|--:|--:|--:|\n",
    );
    for (name, bus) in BUSES {
        let packets = update(bus.link());
        let update_ns = time_ns(bus, packets.iter().copied());
        let load = (update_ns * UPDATE_HZ + cyclic_ns_per_s(bus, PROTOCOL_VERSION)) as f64 / 1e9;
        table += &format!(
            "| {name} | {} | {:.1} µs | {} | {:.1} % |\n",
            packets.len(),
            update_ns as f64 / 1e3,
            1_000_000_000 / update_ns,
            100.0 * load,
        );
    }
    table
}

#[test]
fn the_readme_budget_table_is_what_the_formulas_give() {
    const BEGIN: &str = "<!-- budget:begin (generated by tests/budget.rs) -->\n";
    const END: &str = "<!-- budget:end -->";
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("README.md");
    let readme = std::fs::read_to_string(&path).unwrap();
    let (start, end) = (readme.find(BEGIN).unwrap() + BEGIN.len(), readme.find(END).unwrap());
    let table = budget_table();
    if std::env::var_os("DRESSFORM_BLESS").is_some() {
        std::fs::write(&path, format!("{}{table}{}", &readme[..start], &readme[end..])).unwrap();
    } else {
        assert!(
            readme[start..end] == table,
            "README.md's budget table is out of date; it should read\n{table}\nregenerate it \
             with DRESSFORM_BLESS=1 cargo test -p firmware-protocol --test main budget"
        );
    }
}
