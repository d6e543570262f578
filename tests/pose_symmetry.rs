//! Issue 15, pose symmetry: the body model fitted to MakeHuman bodies posed asymmetrically with
//! MakeHuman's own 163-bone rig (not the model's 21 bones), resampled as a scanner would (no
//! vertex of the template survives), with noise and holes. The recovered limb angles are
//! compared with the posed ones, measured the same way on both rigs: the angle of the limb's
//! joint-to-joint direction in the frontal (XZ) plane.

use crate::common;
use dressform::body_model::BodyModel;
use dressform::fit::{self, FitOptions};
use dressform::makehuman::{MakeHuman, Pose};
use dressform::mesh::Mesh;
use glam::DVec3;
use rand::rngs::ChaCha8Rng;
use rand::{RngExt, SeedableRng};
use rand_distr::{Distribution, Normal};

/// Scan points sampled on the posed skin (a scanner's density on this body: ~10 mm apart).
const SCAN_POINTS: usize = 40_000;
/// The scanner's noise (mm), within issue 15's 0.5-1 mm.
const NOISE_MM: f64 = 0.7;
/// Random holes punched in the scan, and their radius (mm); soles and the top of the head are
/// cut off as well (a scanner sees neither).
const HOLES: usize = 4;
const HOLE_RADIUS_MM: f64 = 30.0;
const CUT_MM: f64 = 15.0;
/// Issue 15's tolerance on recovered arm and leg abduction (degrees).
const LIMB_TOLERANCE_DEG: f64 = 3.0;

/// The body shapes mixed in, including targets the model was not built from.
const SHAPES: [&str; 4] = [
    "bodyshapes/bodyshapes-elvs-fem-apple",
    "bodyshapes/bodyshapes-elvs-man-trapezoid",
    "bodyshapes/bodyshapes-elvs-fem-full-hourglass",
    "asym/asymm-trunk-1-l",
];
const MEASURES: [&str; 4] = [
    "measure/measure-waist-circ-incr",
    "measure/measure-hips-circ-decr",
    "measure/measure-bust-circ-incr",
    "measure/measure-upperarm-circ-incr",
];

/// A limb's angle from straight down in the frontal plane (degrees, outwards positive on
/// both sides), from its upper joint to its lower one.
fn abduction(upper: DVec3, lower: DVec3) -> f64 {
    let d = lower - upper;
    d.x.abs().atan2(-d.z).to_degrees()
}

/// The clavicle's elevation: its direction's angle above the horizontal in the frontal plane.
fn elevation(inner: DVec3, outer: DVec3) -> f64 {
    let d = outer - inner;
    d.z.atan2(d.x.abs()).to_degrees()
}

/// Points with normals sampled uniformly on `mesh`'s surface, with noise and holes.
fn scan_of(mesh: &Mesh, rng: &mut ChaCha8Rng) -> (Vec<DVec3>, Vec<DVec3>) {
    let areas: Vec<f64> = (0..mesh.triangles.len()).map(|t| mesh.triangle_area(t)).collect();
    let mut cumulative = Vec::with_capacity(areas.len());
    let mut total = 0.0;
    for a in &areas {
        total += a;
        cumulative.push(total);
    }
    let noise = Normal::new(0.0, NOISE_MM).unwrap();
    let b = mesh.bounds().unwrap();
    let holes: Vec<DVec3> =
        (0..HOLES).map(|_| mesh.positions[rng.random_range(0..mesh.positions.len())]).collect();
    let (mut points, mut normals) = (Vec::new(), Vec::new());
    for _ in 0..SCAN_POINTS {
        let t =
            cumulative.partition_point(|&c| c < rng.random_range(0.0..total)).min(areas.len() - 1);
        let [a, b2, c] = mesh.corners(t);
        let (mut u, mut v): (f64, f64) = (rng.random_range(0.0..1.0), rng.random_range(0.0..1.0));
        if u + v > 1.0 {
            (u, v) = (1.0 - u, 1.0 - v);
        }
        let jitter = DVec3::new(noise.sample(rng), noise.sample(rng), noise.sample(rng));
        let p = a + u * (b2 - a) + v * (c - a) + jitter;
        let cut = p.z < b.min.z + CUT_MM || p.z > b.max.z - CUT_MM;
        if cut || holes.iter().any(|h| h.distance(p) < HOLE_RADIUS_MM) {
            continue;
        }
        points.push(p - DVec3::Z * b.min.z); // the scan frame's floor at z = 0
        normals.push(mesh.scaled_normal(t).normalize());
    }
    (points, normals)
}

#[test]
fn arm_and_leg_abduction_are_recovered_from_makehuman_scans() {
    let Some(dir) = common::makehuman() else { return };
    let mh = MakeHuman::load(&dir).expect("the MakeHuman assets load");
    let model = BodyModel::builtin();
    let fitted_bone = |name: &str| model.skeleton.names.iter().position(|n| n == name).unwrap();
    let mh_bone = |name: &str| mh.rig.bone(name).unwrap();
    let mut worst: f64 = 0.0;
    for case in 0..3u64 {
        let mut rng = ChaCha8Rng::seed_from_u64(case);
        let targets = [
            (SHAPES[case as usize % SHAPES.len()], rng.random_range(0.3..1.0)),
            (MEASURES[rng.random_range(0..MEASURES.len())], rng.random_range(0.0..0.8)),
        ];
        let body = mh.shaped(&targets).unwrap();
        // One arm 10-20 degrees further out with its shoulder raised, the other side's leg out.
        let (arm, leg, out) = if case % 2 == 0 { (".L", ".R", -1.0) } else { (".R", ".L", 1.0) };
        let arm_deg: f64 = rng.random_range(10.0..20.0);
        let leg_deg: f64 = rng.random_range(3.0..8.0);
        let shoulder_deg: f64 = rng.random_range(3.0..8.0);
        let pose = Pose::rest()
            .rotate(&format!("upperarm01{arm}"), DVec3::Y * (out * arm_deg).to_radians())
            .rotate(&format!("clavicle{arm}"), DVec3::Y * (out * shoulder_deg).to_radians())
            .rotate(&format!("upperleg01{leg}"), DVec3::Y * (-out * leg_deg).to_radians());
        let posed = mh.pose(&body, &pose).unwrap();
        let (points, normals) = scan_of(&mh.base.skin(&posed), &mut rng);
        let truth = mh.rig.bone_heads(&posed);
        let start = std::time::Instant::now();
        let fitted = fit::fit(&model, &points, &normals, &FitOptions::default()).unwrap();
        let seconds = start.elapsed().as_secs_f64();
        let joints = fitted.joints(&model);
        let mut line = format!(
            "case {case} ({targets:?}, arm{arm} +{arm_deg:.1}, shoulder +{shoulder_deg:.1}, leg{leg} +{leg_deg:.1}): {} iterations, {seconds:.2} s, rms {:.2}/{:.2} mm;",
            fitted.iterations, fitted.residuals.model_to_scan_mm, fitted.residuals.scan_to_model_mm
        );
        for side in [".L", ".R"] {
            let limbs = [("upperarm01", "lowerarm01"), ("upperleg01", "lowerleg01")];
            for (upper, lower) in limbs {
                let (u, l) = (format!("{upper}{side}"), format!("{lower}{side}"));
                let want = abduction(truth[mh_bone(&u)], truth[mh_bone(&l)]);
                let got = abduction(joints[fitted_bone(&u)], joints[fitted_bone(&l)]);
                line += &format!(" {u} {want:.1}/{got:.1}");
                worst = worst.max((want - got).abs());
            }
            let (c, u) = (format!("clavicle{side}"), format!("upperarm01{side}"));
            let want = elevation(truth[mh_bone(&c)], truth[mh_bone(&u)]);
            let got = elevation(joints[fitted_bone(&c)], joints[fitted_bone(&u)]);
            line += &format!(" {c} {want:.1}/{got:.1}");
        }
        eprintln!("{line}");
    }
    eprintln!("worst limb abduction error {worst:.2} degrees");
    assert!(worst < LIMB_TOLERANCE_DEG, "worst limb abduction error {worst:.2} degrees");
}
