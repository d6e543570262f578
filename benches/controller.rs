//! A full-form update of the reference form (all 72 actuators, lifts included, on 9 nodes)
//! through the host controller on the in-process simulated bus at 1 Mbit/s (classic CAN and CAN FD 1/5):
//! checking the set-points into safe targets, building the fewest frames, sending them all
//! until the SYNC has crossed the bus.
//!
//! `cargo bench --bench controller` prints, per link: criterion's wall time per update, the
//! host CPU time per update (`getrusage`), and the simulated bus time of the update next to
//! the theoretical worst case from `firmware_protocol::budget`.

use std::collections::BTreeMap;
use std::time::Duration;

use criterion::{Criterion, criterion_group, criterion_main};
use dressform::form::controller::motion::node_targets;
use dressform::form::controller::transport::sim::SimBus;
use dressform::form::controller::{Transport, plan};
use dressform::form::setpoints::SetPoints;
use firmware_protocol::Link;
use firmware_protocol::message::Sync;
use firmware_protocol::update::packets;
use form_description::{FormDescription, reference};
use form_sim::bus::can::{CanBus, CanKind};

fn setpoints(form: &FormDescription) -> SetPoints {
    let positions: BTreeMap<String, f64> = form
        .axes()
        .enumerate()
        .map(|(i, a)| (a.id.to_string(), a.stroke_mm * (0.1 + 0.01 * i as f64)))
        .collect();
    SetPoints::new(form.name.clone(), positions)
}

/// One full-form update: plan, frames, send (queued on the bus in order, as on a SocketCAN
/// socket); then waits until the bus has carried them.
async fn update(form: &FormDescription, setpoints: &SetPoints, bus: &mut SimBus) {
    let (plan, _) = plan(form, setpoints, false).expect("in the stroke");
    let nodes = node_targets(&plan);
    for packet in packets(&nodes, Sync { duration_ms: 2000 }, bus.link()) {
        bus.send(packet).await.expect("sent");
    }
    tokio::time::sleep(Duration::from_millis(5)).await;
}

fn cpu_time() -> Duration {
    // SAFETY: `rusage` is a plain C struct of integers, for which all-zero bytes are valid.
    let mut usage: libc::rusage = unsafe { std::mem::zeroed() };
    // SAFETY: getrusage writes into the struct we own, through a valid exclusive pointer.
    unsafe { libc::getrusage(libc::RUSAGE_SELF, &mut usage) };
    let micros = |t: libc::timeval| t.tv_sec as u64 * 1_000_000 + t.tv_usec as u64;
    Duration::from_micros(micros(usage.ru_utime) + micros(usage.ru_stime))
}

fn theoretical(link: Link, kind: CanKind) -> Duration {
    let form = reference();
    let bus = kind.budget();
    let mut nodes = Vec::new();
    let (plan, _) = plan(&form, &setpoints(&form), false).expect("in the stroke");
    nodes.extend(node_targets(&plan));
    let ns: u64 = packets(&nodes, Sync { duration_ms: 2000 }, link)
        .map(|p| bus.frame_time_ns(p.message.code().payload_len()))
        .sum();
    Duration::from_nanos(ns)
}

fn full_form_update(c: &mut Criterion) {
    let form = reference();
    let setpoints = setpoints(&form);
    for (name, kind) in
        [("classic CAN 1M", CanKind::CLASSIC_1M), ("CAN FD 1M/5M", CanKind::FD_1M_5M)]
    {
        let runtime = tokio::runtime::Builder::new_current_thread()
            .enable_all()
            .start_paused(true)
            .build()
            .expect("runtime");
        let bus = runtime.block_on(async { CanBus::new(kind) });
        let mut port = runtime.block_on(async { SimBus::attach(&bus) });
        // Host CPU and simulated bus time over a fixed number of updates.
        let rounds = 200;
        let cpu_before = cpu_time();
        let wall_before = std::time::Instant::now();
        let stats_before = bus.stats();
        for _ in 0..rounds {
            runtime.block_on(update(&form, &setpoints, &mut port));
        }
        let traffic = bus.stats().since(&stats_before);
        let cpu = (cpu_time() - cpu_before) / rounds;
        let wall = wall_before.elapsed() / rounds;
        println!(
            "{name}: host CPU {:.1} µs/update, wall {:.1} µs/update, {} frames and {:.1} µs of simulated bus time per update, theoretical worst case {:.1} µs",
            cpu.as_secs_f64() * 1e6,
            wall.as_secs_f64() * 1e6,
            traffic.frames / u64::from(rounds),
            (traffic.busy / rounds).as_secs_f64() * 1e6,
            theoretical(kind.link(), kind).as_secs_f64() * 1e6,
        );
        c.bench_function(&format!("full-form update, {name}"), |b| {
            b.iter(|| runtime.block_on(update(&form, &setpoints, &mut port)));
        });
    }
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(20).measurement_time(Duration::from_secs(3));
    targets = full_form_update
}
criterion_main!(benches);
