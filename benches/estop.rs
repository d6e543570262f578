//! The e-stop's latency from another terminal, as a studio meets it: the simulated reference
//! form served on a real pseudo-terminal (serial mapping, and slcan), `dressform drive`
//! moving it in one process, then `dressform estop` started in another; measured from the
//! moment the estop process is started to the moment the last node has latched
//! `EMERGENCY_STOP` (the simulated form's own state, polled every 0.2 ms).
//!
//! `cargo bench --bench estop` runs 20 tries per link (each drive clears the previous
//! e-stop at its start, as the README promises) and prints the median and the largest
//! latency beside criterion's statistics.

use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use criterion::{Criterion, SamplingMode, criterion_group, criterion_main};
use firmware_protocol::drive::Faults;
use form_description::reference;
use sim::serve::{ServeConfig, Server, Transport, serve};

/// Tries per link.
const TRIES: usize = 20;
/// How often the simulated form's state is looked at.
const POLL: Duration = Duration::from_micros(200);

/// One try: start a slow drive, wait until a panel moves, e-stop from another process, wait
/// until every node latched. Returns the latency; the drive must end with status 1.
fn one_try(server: &Server, flag: &str, setpoints: &str) -> Duration {
    // The last try's panels brake to a stop first: "moving" must be this try's move.
    while server.form().state().actuators.iter().any(|a| a.state.moving) {
        std::thread::sleep(Duration::from_millis(2));
    }
    let device = server.device_path().to_str().expect("a pty path");
    let mut drive = Command::new(env!("CARGO_BIN_EXE_dressform"))
        .args(["drive", setpoints, flag, device, "--duration", "20"])
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .expect("dressform drive starts");
    while !server.form().state().actuators.iter().any(|a| a.state.moving) {
        assert!(drive.try_wait().expect("drive").is_none(), "the drive ended before moving");
        std::thread::sleep(Duration::from_millis(2));
    }
    let started = Instant::now();
    let estop = Command::new(env!("CARGO_BIN_EXE_dressform"))
        .args(["estop", flag, device])
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("dressform estop starts");
    let latched = |s: &Server| {
        s.form().state().nodes.iter().all(|n| n.faults.contains(Faults::EMERGENCY_STOP))
    };
    while !latched(server) {
        std::thread::sleep(POLL);
    }
    let latency = started.elapsed();
    let estop = estop.wait_with_output().expect("estop");
    assert!(estop.status.success(), "estop failed: {}", String::from_utf8_lossy(&estop.stderr));
    assert_eq!(drive.wait().expect("drive").code(), Some(1), "the drive must end stopped");
    latency
}

fn estop_latency(c: &mut Criterion) {
    let dir = tempfile::tempdir().expect("a temporary folder");
    let setpoints = dir.path().join("setpoints.json");
    std::fs::write(
        &setpoints,
        r#"{"format": "dressform-setpoints/1", "form": "reference",
            "positions_mm": {"chest-l1": 40, "chest-r1": 40, "waist-front": 30, "hip-back": 30}}"#,
    )
    .expect("the set-point file");
    let setpoints = setpoints.to_str().expect("a path");
    let mut group = c.benchmark_group("estop from another terminal to the last node's latch");
    group
        .sampling_mode(SamplingMode::Flat)
        .sample_size(TRIES)
        .warm_up_time(Duration::from_millis(1))
        .measurement_time(Duration::from_millis(100));
    for (name, transport, flag) in
        [("serial", Transport::SerialPty, "--serial"), ("slcan", Transport::SlcanPty, "--slcan")]
    {
        let server = serve(ServeConfig::new(reference(), transport)).expect("the simulated form");
        let mut latencies = Vec::new();
        group.bench_function(name, |b| {
            b.iter_custom(|iters| {
                (0..iters)
                    .map(|_| {
                        let latency = one_try(&server, flag, setpoints);
                        latencies.push(latency);
                        latency
                    })
                    .sum()
            });
        });
        latencies.sort();
        let ms = |d: Duration| d.as_secs_f64() * 1e3;
        println!(
            "{name}: {} tries, median {:.1} ms, max {:.1} ms (estop started -> last node latched)",
            latencies.len(),
            ms(latencies[latencies.len() / 2]),
            ms(*latencies.last().expect("tries")),
        );
    }
    group.finish();
}

criterion_group!(benches, estop_latency);
criterion_main!(benches);
