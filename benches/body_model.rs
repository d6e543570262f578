//! Benchmarks of the statistical body model: building it from MakeHuman (2,000 bodies, the
//! built-in model's settings; goal < 60 s on 2 cores) and evaluating M(theta, beta) (shape
//! and skinning of the 13,380-vertex template; goal < 1 ms).
//!
//! `cargo bench --bench body_model`; the build needs `../shared/makehuman` (or
//! `$DRESSFORM_MAKEHUMAN`) and is skipped with a message without it.

use criterion::{Criterion, criterion_group, criterion_main};
use dressform::pose::body_model::{self, BodyModel, BuildOptions};
use dressform::pose::makehuman::MakeHuman;
use glam::DVec3;
use std::path::PathBuf;
use std::time::Duration;

fn makehuman() -> Option<PathBuf> {
    let dir = std::env::var_os("DRESSFORM_MAKEHUMAN")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../shared/makehuman"));
    dir.join("base.obj").is_file().then_some(dir)
}

fn evaluate(c: &mut Criterion) {
    let model = BodyModel::builtin();
    let beta: Vec<f64> = (0..model.k()).map(|k| (k as f64 * 0.7).sin()).collect();
    let theta: Vec<DVec3> = (0..model.skeleton.names.len())
        .map(|b| DVec3::new((b as f64).sin(), (b as f64 * 1.3).cos(), 0.5) * 0.2)
        .collect();
    c.bench_function("M(theta, beta): shape + skinning, 13,380 vertices", |b| {
        b.iter(|| model.posed(&beta, &theta, DVec3::new(1.0, 2.0, 3.0)))
    });
}

fn build(c: &mut Criterion) {
    let Some(dir) = makehuman() else {
        eprintln!("SKIPPED: model build: no MakeHuman assets (set DRESSFORM_MAKEHUMAN)");
        return;
    };
    let mut group = c.benchmark_group("model build");
    group.sample_size(10).measurement_time(Duration::from_secs(60));
    group.bench_function("2,000 MakeHuman bodies, k = 15 (assets read included)", |b| {
        b.iter(|| {
            let mh = MakeHuman::load(&dir).expect("the MakeHuman assets load");
            body_model::from_makehuman(&mh, &BuildOptions::default(), &|_, _, _| {})
                .expect("the model builds")
        })
    });
    group.finish();
}

criterion_group!(benches, evaluate, build);
criterion_main!(benches);
