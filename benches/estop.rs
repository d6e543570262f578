//! The e-stop's latency from another terminal, as a studio meets it: the simulated reference
//! form served on a real pseudo-terminal (serial mapping, and slcan), `dressform drive`
//! moving it in one process, then `dressform estop` started in another; measured from the
//! moment the estop process is started to the moment the last node has latched
//! `EMERGENCY_STOP` (the simulated form's own state, polled every 0.2 ms).
//!
//! `cargo bench --bench estop` runs 20 tries per link, with no other client on the drive's
//! control endpoint and with 5 silent clients connected to it (issue 29: the stop within
//! 50 ms regardless), and prints the median and the largest latency beside criterion's
//! statistics. Each drive clears the previous e-stop at its start, as docs/controller-and-safety.md ("Recovery") promises.

use std::os::linux::net::SocketAddrExt;
use std::os::unix::net::{SocketAddr, UnixStream};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use criterion::{Criterion, SamplingMode, criterion_group, criterion_main};
use dressform::form::controller::LinkSpec;
use dressform::form::controller::control::socket_name;
use firmware_protocol::drive::Faults;
use form_description::reference;
use form_sim::serve::{PtyLink, ServeConfig, Server, serve};

/// Tries per link.
const TRIES: usize = 20;
/// How often the simulated form's state is looked at.
const POLL: Duration = Duration::from_micros(200);

/// Silent clients connected to the drive's endpoint in the loaded case.
const SILENT_CLIENTS: usize = 5;

/// One try: start a slow drive, wait until a panel moves, connect `silent` clients to its
/// control endpoint that say nothing, e-stop from another process, wait until every node
/// latched. Returns the latency; the drive must end with status 1.
fn one_try(
    server: &Server,
    spec: &LinkSpec,
    flag: &str,
    setpoints: &str,
    silent: usize,
) -> Duration {
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
    let name = socket_name(spec).expect("a device's endpoint");
    let address = SocketAddr::from_abstract_name(name.as_bytes()).expect("an abstract name");
    let clients: Vec<UnixStream> = (0..silent)
        .map(|_| UnixStream::connect_addr(&address).expect("the drive's endpoint"))
        .collect();
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
    drop(clients);
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
    let links =
        [("serial", PtyLink::SerialPty, "--serial"), ("slcan", PtyLink::SlcanPty, "--slcan")];
    for ((link, transport, flag), silent) in
        links.into_iter().flat_map(|l| [(l, 0), (l, SILENT_CLIENTS)])
    {
        let server = serve(ServeConfig::new(reference(), transport)).expect("the simulated form");
        let path = server.device_path().to_path_buf();
        let spec = if flag == "--serial" { LinkSpec::Serial(path) } else { LinkSpec::Slcan(path) };
        let name = match silent {
            0 => link.to_string(),
            n => format!("{link}, {n} silent clients"),
        };
        let mut latencies = Vec::new();
        group.bench_function(&name, |b| {
            b.iter_custom(|iters| {
                (0..iters)
                    .map(|_| {
                        let latency = one_try(&server, &spec, flag, setpoints, silent);
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
