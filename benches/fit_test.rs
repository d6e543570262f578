//! Garment fit testing on the simulated reference form (issue 30): one fit test (the form
//! shaped to the demo's customer wearing the jersey top, the forces read at rest for 0.5 s)
//! and a 17-step size sweep (-40..+40 mm of girth), each from a fresh power-on (homing
//! included), at the reference form's speeds.
//!
//! Under tokio's paused clock the simulated time is the form's own: how long the actuators,
//! homing and the force window take on a real form. Criterion's wall time is then what the
//! host and the simulator cost to compute it. `cargo bench --bench fit_test` prints both, and
//! the host CPU per run (`getrusage`): the form's time is seconds, the computation a fraction.

use std::path::Path;
use std::time::Duration;

use capture_sim::{BodyParams, generate};
use criterion::{Criterion, criterion_group, criterion_main};
use dressform::body::mesh::Mesh;
use dressform::body::scan::{self, frame::FrameOptions};
use dressform::form::controller::simulated::{SimConfig, SimulatedRig};
use dressform::form::controller::{Claim, DEFAULT_FORCE_WINDOW, DriveOptions};
use dressform::form::fit_test::sweep::{self, DEFAULT_SWEEP, SweepRange};
use dressform::form::form_fit::fit;
use dressform::form::setpoints::SetPoints;
use dressform::run::pipeline::symmetrize;
use dressform::shape::mannequin::MannequinOptions;
use dressform::shape::profiles::Profiles;
use form_description::garment::{GarmentSpec, shipped};
use form_description::{FormDescription, reference};
use glam::DVec3;

/// The demo's customer's set-points on the reference form.
fn customer(form: &FormDescription) -> SetPoints {
    let body = generate(&BodyParams::default()).expect("the default body generates");
    let mesh = Mesh::new(
        body.surface.positions.iter().map(|&p| DVec3::from_array(p)).collect(),
        body.surface.triangles,
    );
    let scan = scan::from_mesh(mesh, Path::new("customer"), &FrameOptions::default())
        .expect("a clean body");
    let out = symmetrize(&scan, &MannequinOptions::default(), |_| {}).expect("a mannequin");
    let profiles = Profiles::of(&out.mannequin, &out.comparison.levels);
    fit(&profiles, form).expect("the form fits").setpoints()
}

/// Powers the form on wearing `garment`, drives it through `steps` reading the forces at
/// each; returns the simulated time it took.
async fn run(form: &FormDescription, garment: &GarmentSpec, steps: &[SetPoints]) -> Duration {
    let start = tokio::time::Instant::now();
    let rig = SimulatedRig::start(form, &SimConfig::default().wearing(Some(garment.clone())))
        .expect("sim");
    let claim = Claim::take(rig.attach(), form).await.expect("claimed");
    let options = DriveOptions { read_forces: Some(DEFAULT_FORCE_WINDOW), ..Default::default() };
    claim.drive_through(steps, &options, |_| {}).await.expect("driven");
    start.elapsed()
}

fn cpu_time() -> Duration {
    // SAFETY: `rusage` is a plain C struct of integers, for which all-zero bytes are valid.
    let mut usage: libc::rusage = unsafe { std::mem::zeroed() };
    // SAFETY: getrusage writes into the struct we own, through a valid exclusive pointer.
    unsafe { libc::getrusage(libc::RUSAGE_SELF, &mut usage) };
    let micros = |t: libc::timeval| t.tv_sec as u64 * 1_000_000 + t.tv_usec as u64;
    Duration::from_micros(micros(usage.ru_utime) + micros(usage.ru_stime))
}

fn fit_tests(c: &mut Criterion) {
    let form = reference();
    let base = customer(&form);
    let garment =
        GarmentSpec::from_toml_str(shipped("jersey-top").expect("shipped"), &form).expect("valid");
    let range: SweepRange = DEFAULT_SWEEP.parse().expect("the default sweep");
    let swept: Vec<SetPoints> =
        range.deltas().iter().map(|&d| sweep::step_setpoints(&form, &garment, &base, d)).collect();
    for (name, steps) in [("fit test", vec![base.clone()]), ("17-step sweep", swept)] {
        let runtime = tokio::runtime::Builder::new_current_thread()
            .enable_all()
            .start_paused(true)
            .build()
            .expect("runtime");
        let (cpu_before, wall_before) = (cpu_time(), std::time::Instant::now());
        let simulated = runtime.block_on(run(&form, &garment, &steps));
        println!(
            "{name}: {:.1} s of the form's time (moves, homing, force windows); host and \
             simulator {:.2} s CPU, {:.2} s wall",
            simulated.as_secs_f64(),
            (cpu_time() - cpu_before).as_secs_f64(),
            wall_before.elapsed().as_secs_f64()
        );
        c.bench_function(name, |b| b.iter(|| runtime.block_on(run(&form, &garment, &steps))));
    }
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(10).measurement_time(Duration::from_secs(10));
    targets = fit_tests
}
criterion_main!(benches);
