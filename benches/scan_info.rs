//! What `dressform info` does to a scan file — decode the binary PLY, clean, find the canonical
//! frame, analyse the topology — on meshes of 10k, 100k and 1M triangles of two kinds: a closed
//! body-sized ellipsoid (every vertex a small normal fan) and a cone whose triangles all meet at
//! its apex (one fan of n triangles round one vertex, issue 16). Linear time shows as a time per
//! triangle ("thrpt") that stays flat from 10k to 1M.
//!
//! `cargo bench --bench scan_info`

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use dressform::body::mesh::Mesh;
use dressform::body::scan::{self, format::Format, frame::FrameOptions};
use dressform::run::info::ScanInfo;
use glam::DVec3;
use std::f64::consts::{PI, TAU};
use std::path::Path;
use std::time::Duration;

/// A standing adult's height (m), so the frame finds metres.
const HEIGHT: f64 = 1.7;

/// A closed ellipsoid, 1.7 m tall, of about `triangles` triangles (a UV sphere).
fn ellipsoid(triangles: usize) -> Mesh {
    let rings = ((triangles as f64 / 4.0).sqrt() as u32).max(3);
    let segments = 2 * rings;
    let mut m = Mesh::default();
    m.positions.push(DVec3::new(0.0, 0.0, 0.0));
    for j in 1..rings {
        let phi = PI * f64::from(j) / f64::from(rings);
        for i in 0..segments {
            let t = TAU * f64::from(i) / f64::from(segments);
            let (x, y, z) = (phi.sin() * t.cos(), phi.sin() * t.sin(), 1.0 - phi.cos());
            m.positions.push(DVec3::new(0.2 * x, 0.12 * y, 0.5 * HEIGHT * z));
        }
    }
    m.positions.push(DVec3::new(0.0, 0.0, HEIGHT));
    let ring = |j: u32, i: u32| 1 + (j - 1) * segments + i % segments;
    let top = (rings - 1) * segments + 1;
    for i in 0..segments {
        m.triangles.push([0, ring(1, i + 1), ring(1, i)]);
        for j in 1..rings - 1 {
            m.triangles.push([ring(j, i), ring(j, i + 1), ring(j + 1, i + 1)]);
            m.triangles.push([ring(j, i), ring(j + 1, i + 1), ring(j + 1, i)]);
        }
        m.triangles.push([ring(rings - 1, i), ring(rings - 1, i + 1), top]);
    }
    m
}

/// A cone of `triangles` triangles, all round its apex (open at the base).
fn cone(triangles: usize) -> Mesh {
    let n = triangles as u32;
    let mut m = Mesh::default();
    m.positions.push(DVec3::new(0.0, 0.0, HEIGHT));
    m.positions.extend((0..n).map(|i| {
        let a = TAU * f64::from(i) / f64::from(n);
        DVec3::new(0.3 * a.cos(), 0.3 * a.sin(), 0.0)
    }));
    m.triangles.extend((0..n).map(|i| [0, 1 + i, 1 + (i + 1) % n]));
    m
}

/// `info` on the PLY bytes.
fn info(bytes: &[u8]) -> ScanInfo {
    let s = scan::from_bytes(bytes, Path::new("bench.ply"), &FrameOptions::default());
    ScanInfo::new(&s.expect("a readable scan"))
}

fn bench(c: &mut Criterion) {
    let mut group = c.benchmark_group("info");
    group.sample_size(10).warm_up_time(Duration::from_secs(1));
    for (kind, make) in [("ellipsoid", ellipsoid as fn(usize) -> Mesh), ("fan", cone)] {
        for n in [10_000, 100_000, 1_000_000] {
            let mesh = make(n);
            let bytes = Format::Ply.encode(&mesh);
            group.throughput(Throughput::Elements(mesh.triangles.len() as u64));
            group.bench_with_input(BenchmarkId::new(kind, n), &bytes, |b, bytes| {
                b.iter(|| info(bytes))
            });
        }
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
