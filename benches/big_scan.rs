//! A high-resolution scanner's scan through `reconstruct` (issue 32): 5 million triangles, as
//! a whole process (`dressform reconstruct scan.stl -o out`, reading, decimating to the working
//! density, pose symmetry, the mannequin and its eight outputs). Goal: at most 15 s and 1 GB
//! of peak memory on 2 cores.
//!
//! The scan: the synthetic customer as the typical scanner sees it (noise, holes, the soles
//! and crown cut: `capture_sim`), each triangle split in four twice (4.8M triangles), the new
//! vertices moved by the scanner's noise, written as binary STL as such scanners export.
//! `cargo bench --bench big_scan` prints criterion's wall time and the largest child's peak
//! resident memory (`getrusage(RUSAGE_CHILDREN)`).

use std::collections::HashMap;
use std::path::Path;
use std::process::Command;
use std::time::{Duration, Instant};

use capture_sim::{Artifacts, BodyParams, capture, generate};
use criterion::{Criterion, criterion_group, criterion_main};
use dressform::body::mesh::Mesh;
use dressform::body::scan::format::Format;
use glam::DVec3;
use rand::{RngExt, SeedableRng, rngs::ChaCha8Rng};

/// The goals of issue 32.
const GOAL: Duration = Duration::from_secs(15);
const GOAL_RSS_BYTES: u64 = 1_000_000_000;
/// The noise given to the vertices the splits add (per axis, uniform; in metres, the units the
/// simulated scanner writes): 0.5 mm, about the typical scanner's
/// ([`Artifacts::typical_scanner`]).
const NOISE_M: f64 = 0.5e-3;

/// Each triangle of `mesh` split in four at its edges' midpoints (shared between neighbours),
/// the midpoints moved by up to [`NOISE_M`].
fn split(mesh: &Mesh, rng: &mut ChaCha8Rng) -> Mesh {
    let mut out = Mesh { positions: mesh.positions.clone(), triangles: Vec::new() };
    let mut midpoints: HashMap<(u32, u32), u32> = HashMap::new();
    let mut midpoint = |a: u32, b: u32, out: &mut Mesh| {
        *midpoints.entry((a.min(b), a.max(b))).or_insert_with(|| {
            let jitter = DVec3::from_array([0; 3].map(|_| rng.random_range(-NOISE_M..NOISE_M)));
            let p = 0.5 * (out.positions[a as usize] + out.positions[b as usize]) + jitter;
            out.positions.push(p);
            out.positions.len() as u32 - 1
        })
    };
    for &[a, b, c] in &mesh.triangles {
        let (ab, bc, ca) =
            (midpoint(a, b, &mut out), midpoint(b, c, &mut out), midpoint(c, a, &mut out));
        out.triangles.extend([[a, ab, ca], [ab, b, bc], [ca, bc, c], [ab, bc, ca]]);
    }
    out
}

/// Writes the 5M-triangle scan into `dir`.
fn big_scan(dir: &Path) -> std::path::PathBuf {
    let body = generate(&BodyParams::default()).expect("the default body generates");
    let raw = capture(&body, &Artifacts::typical_scanner(1));
    let scan =
        Mesh::new(raw.positions.iter().map(|&p| DVec3::from_array(p)).collect(), raw.triangles);
    let mut rng = ChaCha8Rng::seed_from_u64(32);
    let dense = split(&split(&scan, &mut rng), &mut rng);
    eprintln!("the scan: {} triangles", dense.triangles.len());
    let path = dir.join("scan.stl");
    std::fs::write(&path, Format::Stl.encode(&dense)).expect("writable");
    path
}

/// The largest peak resident memory of the children waited for so far (bytes).
fn children_peak_rss() -> u64 {
    // SAFETY: `rusage` is a plain C struct of integers, for which all-zero bytes are valid.
    let mut usage: libc::rusage = unsafe { std::mem::zeroed() };
    // SAFETY: getrusage writes into the struct we own, through a valid exclusive pointer.
    unsafe { libc::getrusage(libc::RUSAGE_CHILDREN, &mut usage) };
    usage.ru_maxrss as u64 * 1024
}

fn bench(c: &mut Criterion) {
    let tmp = tempfile::tempdir().expect("a temporary folder");
    let scan = big_scan(tmp.path());
    let out = tmp.path().join("out");
    let run = || {
        let start = Instant::now();
        let status = Command::new(env!("CARGO_BIN_EXE_dressform"))
            .args(["reconstruct", scan.to_str().unwrap(), "-o", out.to_str().unwrap(), "--json"])
            .stdout(std::process::Stdio::null())
            .status()
            .expect("dressform runs");
        assert!(status.success(), "reconstruct failed");
        start.elapsed()
    };
    let mut group = c.benchmark_group("big_scan");
    group.sample_size(10).measurement_time(Duration::from_secs(120));
    group.bench_function("reconstruct_5m_triangles", |b| {
        b.iter_custom(|iters| (0..iters).map(|_| run()).sum())
    });
    group.finish();
    let rss = children_peak_rss();
    println!(
        "peak resident memory of reconstruct: {:.0} MB (goal {:.0} MB); wall time goal {GOAL:?}",
        rss as f64 / 1e6,
        GOAL_RSS_BYTES as f64 / 1e6
    );
}

criterion_group!(benches, bench);
criterion_main!(benches);
