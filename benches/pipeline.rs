//! Benchmarks of the scan side on the realistic MakeHuman body, subdivided to scanner
//! density: slicing alone, the full `symmetrize` (alone, and with the pictures it writes:
//! `preview.png` and `sections.svg`), and the whole `dressform slice` process; then
//! `reconstruct` (issue 15) of the demo's asymmetrically standing customer at about 300k
//! triangles: the fit alone, the library call, and the whole `dressform reconstruct` process
//! with its outputs.
//!
//! `cargo bench --bench pipeline`; needs `../shared/makehuman` (or `$DRESSFORM_MAKEHUMAN`).

use criterion::{Criterion, criterion_group, criterion_main};
use dressform::body::mesh::Mesh;
use dressform::body::scan::format::Format;
use dressform::body::scan::{self, frame::FrameOptions};
use dressform::body::slice::sections;
use dressform::run::pipeline::symmetrize;
use dressform::run::preview::{preview_png, sections_svg};
use dressform::shape::mannequin::MannequinOptions;
use glam::DVec3;
use std::path::PathBuf;
use std::time::Duration;

fn makehuman() -> Option<PathBuf> {
    let dir = std::env::var_os("DRESSFORM_MAKEHUMAN")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../shared/makehuman"));
    dir.join("base.obj").is_file().then_some(dir)
}

/// Splits every triangle into `k * k` (points summed in vertex-index order, so that both
/// triangles along an edge create bit-identical points and the result welds watertight).
fn subdivide(m: &Mesh, k: u32) -> Mesh {
    let mut out = Mesh::default();
    for tri in &m.triangles {
        let mut rows: Vec<Vec<u32>> = Vec::new();
        for i in 0..=k {
            let mut row = Vec::new();
            for j in 0..=k - i {
                let weights = [k - i - j, i, j];
                let mut terms: Vec<(u32, u32)> = (0..3).map(|c| (tri[c], weights[c])).collect();
                terms.sort_unstable();
                let p = terms.iter().fold(DVec3::ZERO, |acc, &(v, w)| {
                    acc + m.positions[v as usize] * (w as f64 / k as f64)
                });
                row.push(out.positions.len() as u32);
                out.positions.push(p);
            }
            rows.push(row);
        }
        for i in 0..k as usize {
            for j in 0..k as usize - i {
                out.triangles.push([rows[i][j], rows[i + 1][j], rows[i][j + 1]]);
                if j + 1 < k as usize - i {
                    out.triangles.push([rows[i + 1][j], rows[i + 1][j + 1], rows[i][j + 1]]);
                }
            }
        }
    }
    out.weld_identical();
    out
}

fn planes(height: f64, n: usize) -> Vec<f64> {
    (0..n).map(|i| height * (i as f64 + 0.5) / n as f64).collect()
}

fn benches(c: &mut Criterion) {
    let Some(dir) = makehuman() else {
        eprintln!("SKIPPED: MakeHuman assets not found (set DRESSFORM_MAKEHUMAN)");
        return;
    };
    let base = scan::load(&dir.join("base.obj"), &FrameOptions::default())
        .expect("the MakeHuman body loads");
    let body = subdivide(&base.body, 4);
    let height = base.frame.height_mm;
    let heights = planes(height, 200);
    let mut group = c.benchmark_group("scan");
    group.sample_size(20);
    group.bench_function(format!("slice {} triangles at 200 planes", body.triangles.len()), |b| {
        b.iter(|| sections(&body, &heights))
    });

    let dense = scan::from_mesh(body, &dir.join("base.obj"), &FrameOptions::default())
        .expect("subdivided body");
    group.bench_function(format!("symmetrize {} triangles", dense.body.triangles.len()), |b| {
        b.iter(|| symmetrize(&dense, &MannequinOptions::default(), |_| {}).expect("symmetrize"))
    });
    // What `dressform symmetrize` computes: the mannequin and both pictures (target: < 1 s).
    group.bench_function(
        format!(
            "symmetrize {} triangles with preview.png and sections.svg",
            dense.body.triangles.len()
        ),
        |b| {
            b.iter(|| {
                let result =
                    symmetrize(&dense, &MannequinOptions::default(), |_| {}).expect("symmetrize");
                (preview_png(&[(&dense.body, "scan")], &result), sections_svg(&dense.body, &result))
            })
        },
    );

    // The whole process on a binary PLY of about a million triangles, in the file's units.
    let million = subdivide(&base.body, 6).map_positions(|p| base.frame.to_scan(p));
    let tmp = tempfile::tempdir().expect("temporary directory");
    let ply = tmp.path().join("scan.ply");
    std::fs::write(&ply, Format::Ply.encode(&million)).expect("write the PLY");
    let list: Vec<String> = planes(height, 200).iter().map(|h| format!("{h:.2}")).collect();
    let list = list.join(",");
    stage_benches(&mut group, &ply, &planes(height, 200));
    group.measurement_time(Duration::from_secs(10));
    group.bench_function(
        format!("dressform slice process, {} triangles, 200 planes", million.triangles.len()),
        |b| {
            b.iter(|| {
                let out = std::process::Command::new(env!("CARGO_BIN_EXE_dressform"))
                    .args([
                        "slice",
                        ply.to_str().expect("utf-8 path"),
                        "--heights",
                        &list,
                        "--json",
                    ])
                    .output()
                    .expect("dressform runs");
                assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
            })
        },
    );
    group.finish();
}

/// The stages of the whole `dressform slice` process one by one (issue 36), on the same file
/// and planes, so that a regression shows in the stage it is in: decoding the PLY, cleaning,
/// the canonical frame, the topology check (beside the rest in the process), the sweep of the
/// tracking levels and the requested planes, and the region tracking with that sweep.
fn stage_benches(
    group: &mut criterion::BenchmarkGroup<criterion::measurement::WallTime>,
    ply: &std::path::Path,
    heights: &[f64],
) {
    use criterion::BatchSize;
    use dressform::body::mesh::topology;
    use dressform::body::regions::{BodyRegions, TRACKING_STEP_MM};
    use dressform::body::scan::{clean::clean, frame::detect};
    let bytes = std::fs::read(ply).expect("read the PLY");
    let read = Format::Ply.decode(&bytes).expect("decode the PLY").mesh;
    let n = read.triangles.len();
    group.bench_function(format!("slice stage: decode the PLY, {n} triangles"), |b| {
        b.iter(|| Format::Ply.decode(&bytes).expect("decode"))
    });
    group.bench_function(format!("slice stage: clean, {n} triangles"), |b| {
        b.iter_batched(|| read.clone(), |m| clean(m).expect("clean"), BatchSize::LargeInput)
    });
    let scan = scan::from_mesh(read.clone(), ply, &FrameOptions::default()).expect("the body");
    group.bench_function(format!("slice stage: canonical frame, {n} triangles"), |b| {
        b.iter(|| detect(&read, &FrameOptions::default()).expect("a frame"))
    });
    group.bench_function(format!("slice stage: topology check, {n} triangles"), |b| {
        b.iter(|| topology(&scan.body))
    });
    let step = TRACKING_STEP_MM;
    let levels = (scan.frame.height_mm / step).floor() as usize;
    let tracking: Vec<f64> = (0..levels).map(|i| step * (i as f64 + 0.5)).collect();
    let all = [&tracking[..], heights].concat();
    group.bench_function(
        format!("slice stage: sweep of {} tracking levels and {} planes", levels, heights.len()),
        |b| b.iter(|| sections(&scan.body, &all)),
    );
    group.bench_function("slice stage: regions (the sweep and the tracking)", |b| {
        b.iter(|| BodyRegions::find_and_cut(&scan.body, step, heights))
    });
}

/// `reconstruct` (issue 15: a scan of about 300k triangles, the whole process <= 3 s, the fit
/// <= 2 s) on the demo's customer: the sim generator's default body, meshed at its 4 mm grid
/// (about 300k triangles), standing with the left arm 15 degrees and the right leg 5 degrees
/// further out, captured with a typical scanner's noise and holes and written as binary PLY.
fn reconstruct_benches(c: &mut Criterion) {
    use capture_sim::{Artifacts, BodyParams, capture, generate};
    use dressform::pose::body_model::BodyModel;
    use dressform::pose::model_fit::{self, FitOptions, ScanPoints};
    use dressform::run::reconstruct::{ReconstructOptions, reconstruct};
    let mut params = BodyParams::default();
    params.pose.left_arm.abduction_deg += 15.0;
    params.pose.right_leg.abduction_deg += 5.0;
    let body = generate(&params).expect("the demo customer generates");
    let raw = capture(&body, &Artifacts::typical_scanner(0));
    let mesh =
        Mesh::new(raw.positions.iter().map(|&p| DVec3::from_array(p)).collect(), raw.triangles);
    let n = mesh.triangles.len();
    let tmp = tempfile::tempdir().expect("temporary directory");
    let ply = tmp.path().join("scan.ply");
    std::fs::write(&ply, Format::Ply.encode(&mesh)).expect("write the PLY");
    let scan = scan::load(&ply, &FrameOptions::default()).expect("the scan loads");
    let model = BodyModel::builtin();
    let mut group = c.benchmark_group("reconstruct");
    group.sample_size(10);
    let extended = model_fit::segment_lengths::extended(&model);
    group.bench_function(format!("fit alone, {n} triangles"), |b| {
        b.iter(|| {
            let points = ScanPoints::of_mesh(&scan.body);
            model_fit::fit(&extended, &points, &FitOptions::default()).expect("fit")
        })
    });
    group.bench_function(format!("reconstruct (library), {n} triangles"), |b| {
        b.iter(|| {
            reconstruct(&scan, &model, &ReconstructOptions::default(), |_| {}).expect("reconstruct")
        })
    });
    let out = tmp.path().join("out");
    group.bench_function(format!("dressform reconstruct process, {n} triangles"), |b| {
        b.iter(|| {
            let run = std::process::Command::new(env!("CARGO_BIN_EXE_dressform"))
                .args(["reconstruct", ply.to_str().expect("utf-8 path"), "-o"])
                .arg(&out)
                .output()
                .expect("dressform runs");
            assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
        })
    });
    group.finish();
}

criterion_group!(pipeline, benches, reconstruct_benches);
criterion_main!(pipeline);
