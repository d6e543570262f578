//! Segmentation: the armholes (armpit and shoulder point per side) against the sim
//! generator's known landmarks and on the MakeHuman body, and the torso sections they clip —
//! no arm material, no width jump where the arm is cut off.

use crate::common;

use capture_sim::{BodyParams, Pose, generate};
use common::{makehuman, mesh_of};
use dressform::body::regions::Armhole;
use dressform::body::scan::{self, frame::FrameOptions};
use dressform::body::segmented_body::SegmentedBody;
use glam::DVec3;

/// Spacing of the torso sections compared for the width jump (the mannequin's own rule).
const JUMP_STEP_MM: f64 = 2.0;
/// The largest change of a smooth body's half-width between sections 2 mm apart (mm).
const SMOOTH_JUMP_MM: f64 = 15.0;

/// What the torso sections between the lower armpit and the higher shoulder point (where the
/// armholes cut) look like.
struct TorsoShape {
    /// Largest change of either half-width between neighbouring sections (mm) and where.
    jump: (f64, f64),
    /// Farthest reach of the torso outward on each side (left, right) above the armpits.
    reach: [f64; 2],
}

fn torso_shape(body: &SegmentedBody) -> TorsoShape {
    let m = body.landmarks();
    let lo = m.left_armpit.min(m.right_armpit) - 30.0;
    let hi = m.left_armhole.shoulder_point.z.max(m.right_armhole.shoulder_point.z);
    let count = ((hi - lo) / JUMP_STEP_MM) as usize;
    let zs: Vec<f64> = (0..count).map(|k| lo + JUMP_STEP_MM * k as f64).collect();
    let loops = body.torso_sections(&zs);
    let half_widths: Vec<(f64, [f64; 2])> = zs
        .iter()
        .zip(&loops)
        .map(|(&z, c)| {
            let c = c.as_ref().unwrap_or_else(|| panic!("no torso section at {z:.0}"));
            let left = c.points.iter().map(|p| p.x - m.centre_x).fold(f64::MIN, f64::max);
            let right = c.points.iter().map(|p| m.centre_x - p.x).fold(f64::MIN, f64::max);
            (z, [left, right])
        })
        .collect();
    let jump = half_widths
        .windows(2)
        .flat_map(|w| (0..2).map(move |s| ((w[1].1[s] - w[0].1[s]).abs(), w[1].0)))
        .fold((0.0, 0.0), |a: (f64, f64), b| if b.0 > a.0 { b } else { a });
    let above = |s: usize, armpit: f64| {
        half_widths.iter().filter(|(z, _)| *z > armpit).map(|(_, w)| w[s]).fold(0.0, f64::max)
    };
    TorsoShape { jump, reach: [above(0, m.left_armpit), above(1, m.right_armpit)] }
}

/// A joint of MakeHuman's default skeleton in the canonical frame: the mean of the base-mesh
/// vertices the rig lists for it.
fn makehuman_joint(
    dir: &std::path::Path,
    name: &str,
    frame: &dressform::body::scan::frame::CanonicalFrame,
) -> DVec3 {
    let rig: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("rigs/default.mhskel")).unwrap())
            .unwrap();
    let obj = std::fs::read_to_string(dir.join("base.obj")).unwrap();
    let vertices: Vec<DVec3> = obj
        .lines()
        .filter_map(|l| l.strip_prefix("v "))
        .map(|l| {
            let c: Vec<f64> = l.split_whitespace().map(|t| t.parse().unwrap()).collect();
            DVec3::new(c[0], c[1], c[2])
        })
        .collect();
    let ids = rig["joints"][name].as_array().unwrap();
    let sum: DVec3 = ids.iter().map(|i| vertices[i.as_u64().unwrap() as usize]).sum();
    frame.to_canonical(sum / ids.len() as f64)
}

fn describe(name: &str, side: &str, a: &Armhole) {
    println!(
        "{name} {side}: armpit ({:.1}, {:.1}, {:.1}), shoulder point ({:.1}, {:.1}, {:.1}), normal ({:.2}, {:.2}, {:.2})",
        a.armpit.x,
        a.armpit.y,
        a.armpit.z,
        a.shoulder_point.x,
        a.shoulder_point.y,
        a.shoulder_point.z,
        a.normal.x,
        a.normal.y,
        a.normal.z
    );
}

/// Tolerances against the generator's landmarks (mm). The armpit is where the arm's loop
/// first joins the torso's (the lowest point of the saddle between them); the generator's is
/// the top of the gap in the shoulder joint's frontal plane, a little off the saddle's lowest
/// point when the arm is swung forward or back. The generator's acromion is a design point (x = half the shoulder
/// width) inside a smooth blend of trapezius, deltoid and arm, with no corner of its own on
/// some bodies; the shoulder point is the corner of the silhouette, which lands on it within
/// a few millimetres on most bodies and within 25 mm where the shoulder rounds over gradually.
const ARMPIT_TOLERANCE_MM: f64 = 15.0;
const SHOULDER_X_TOLERANCE_MM: f64 = 25.0;
const SHOULDER_Z_TOLERANCE_MM: f64 = 25.0;

/// Checks the armholes of a generated body against its truth; returns the worst errors
/// (armpit distance, shoulder point x, shoulder point z, width jump).
fn check_generated(name: &str, params: &BodyParams) -> [f64; 4] {
    let body = generate(params).unwrap_or_else(|e| panic!("{name}: {e}"));
    let mesh = mesh_of(&body);
    let segmented = SegmentedBody::find(&mesh).unwrap_or_else(|e| panic!("{name}: {e}"));
    let m = segmented.landmarks();
    let lm = &body.truth.landmarks;
    let mut worst = [0.0f64; 4];
    for (side, a, truth) in
        [("left", &m.left_armhole, &lm.left), ("right", &m.right_armhole, &lm.right)]
    {
        describe(name, side, a);
        let pit = DVec3::from_array(truth.armpit);
        let acromion = DVec3::from_array(truth.acromion);
        let e = [
            a.armpit.distance(pit),
            (a.shoulder_point.x - acromion.x).abs(),
            (a.shoulder_point.z - acromion.z).abs(),
        ];
        println!(
            "{name} {side}: armpit off by {:.1} mm, shoulder point off by {:+.1} mm in x, {:+.1} mm in z",
            e[0],
            a.shoulder_point.x - acromion.x,
            a.shoulder_point.z - acromion.z
        );
        assert!(e[0] < ARMPIT_TOLERANCE_MM, "{name} {side}: armpit {pit} vs {}", a.armpit);
        assert!(e[1] < SHOULDER_X_TOLERANCE_MM, "{name} {side}: shoulder x");
        assert!(e[2] < SHOULDER_Z_TOLERANCE_MM, "{name} {side}: shoulder z");
        for k in 0..3 {
            worst[k] = worst[k].max(e[k]);
        }
        assert!(
            (a.armpit.z - if side == "left" { m.left_armpit } else { m.right_armpit }).abs() < 1e-9
        );
    }
    let shape = torso_shape(&segmented);
    println!(
        "{name}: width jump {:.1} mm at z = {:.0}; torso reaches {:.1} / {:.1} mm out above the armpits (acromions at {:.1} / {:.1})",
        shape.jump.0,
        shape.jump.1,
        shape.reach[0],
        shape.reach[1],
        lm.left.acromion[0],
        -lm.right.acromion[0]
    );
    assert!(
        shape.jump.0 <= SMOOTH_JUMP_MM,
        "{name}: width jump {:.1} mm at {:.0}",
        shape.jump.0,
        shape.jump.1
    );
    // No arm material: above the armpit the torso reaches no farther out than the shoulder
    // point or the armpit (a raised arm's armpit lies outside the shoulder point).
    for (s, truth) in [(0, &lm.left), (1, &lm.right)] {
        let limit = truth.acromion[0].abs().max(truth.armpit[0].abs());
        assert!(
            shape.reach[s] <= limit + ARMPIT_TOLERANCE_MM,
            "{name}: side {s} reaches {:.1}",
            shape.reach[s]
        );
    }
    worst[3] = shape.jump.0;
    worst
}

#[test]
fn armholes_of_generated_bodies_in_the_a_pose_and_asymmetric() {
    let mut bodies: Vec<(String, BodyParams)> = vec![
        ("default".into(), BodyParams::default()),
        (
            "asymmetric".into(),
            BodyParams { pose: Pose::asymmetric_example(), ..BodyParams::default() },
        ),
    ];
    bodies.extend((0..4).map(|s| (format!("random {s}"), BodyParams::random(s))));
    let mut worst = [0.0f64; 4];
    for (name, params) in &bodies {
        let w = check_generated(name, params);
        for k in 0..4 {
            worst[k] = worst[k].max(w[k]);
        }
    }
    println!(
        "worst over {} bodies: armpit {:.1} mm, shoulder point x {:.1} mm, z {:.1} mm, width jump {:.1} mm",
        bodies.len(),
        worst[0],
        worst[1],
        worst[2],
        worst[3]
    );
}

#[test]
fn armholes_of_the_makehuman_body_are_mirror_images() {
    let Some(dir) = makehuman() else { return };
    let scan = scan::load(&dir.join("base.obj"), &FrameOptions::default()).unwrap();
    let segmented = SegmentedBody::find(&scan.body).unwrap();
    let m = segmented.landmarks();
    describe("makehuman", "left", &m.left_armhole);
    describe("makehuman", "right", &m.right_armhole);
    let mirror = |p: DVec3| DVec3::new(2.0 * m.centre_x - p.x, p.y, p.z);
    let (l, r) = (&m.left_armhole, &m.right_armhole);
    assert!(l.armpit.distance(mirror(r.armpit)) < 2.0, "armpits mirror each other");
    assert!(l.shoulder_point.distance(mirror(r.shoulder_point)) < 2.0);
    let width = l.shoulder_point.x - r.shoulder_point.x;
    println!("makehuman: shoulder width (biacromial) {width:.1} mm");
    // MakeHuman's default adult is 1.67 m tall: biacromial breadth 0.2-0.25 of the stature.
    assert!((0.20..0.25).contains(&(width / m.height)), "{width}");
    // The plate tilts outward going up, as an armhole does in front view.
    assert!(l.shoulder_point.x > l.armpit.x && l.shoulder_point.z > l.armpit.z + 50.0);
    // Against MakeHuman's own skeleton: the shoulder point sits above and outside the
    // shoulder joint (the head of `upperarm01.L`), as the acromion does (10-40 mm out,
    // 20-60 mm up in adults).
    let joint = makehuman_joint(&dir, "upperarm01.L____head", &scan.frame);
    println!("makehuman: left shoulder joint ({:.1}, {:.1}, {:.1})", joint.x, joint.y, joint.z);
    let (out, up) = (l.shoulder_point.x - joint.x, l.shoulder_point.z - joint.z);
    assert!((10.0..40.0).contains(&out) && (20.0..60.0).contains(&up), "{out:.1} out, {up:.1} up");
    let shape = torso_shape(&segmented);
    println!(
        "makehuman: width jump {:.1} mm at z = {:.0}; reach {:.1} / {:.1}",
        shape.jump.0, shape.jump.1, shape.reach[0], shape.reach[1]
    );
    assert!(shape.jump.0 <= SMOOTH_JUMP_MM);
    assert!(shape.reach[0] <= l.shoulder_point.x - m.centre_x + 1e-6);
}

#[test]
fn slice_labels_the_untouched_makehuman_body() {
    let Some(dir) = makehuman() else { return };
    let base = dir.join("base.obj");
    let (code, stdout, stderr) = common::dressform(&[
        "slice",
        base.to_str().unwrap(),
        "--smooth",
        "0",
        "--json",
        "--heights",
        "300,900,1100,1620",
    ]);
    assert_eq!(code, 0, "{stderr}");
    let out: serde_json::Value = serde_json::from_str(&stdout).unwrap();
    // Per plane, the labels expected (left is +x): legs, torso, torso and both arms, head.
    let expected: [&[&str]; 4] =
        [&["left_leg", "right_leg"], &["torso"], &["left_arm", "right_arm", "torso"], &["head"]];
    for (section, want) in out["sections"].as_array().unwrap().iter().zip(expected) {
        let loops = section["loops"].as_array().unwrap();
        let mut labels: Vec<&str> = loops.iter().map(|l| l["label"].as_str().unwrap()).collect();
        for l in loops {
            let x = l["centroid_mm"][0].as_f64().unwrap();
            match l["label"].as_str().unwrap() {
                "left_leg" | "left_arm" => assert!(x > 50.0, "{l}"),
                "right_leg" | "right_arm" => assert!(x < -50.0, "{l}"),
                _ => assert!(x.abs() < 30.0, "{l}"),
            }
        }
        labels.sort_unstable();
        labels.dedup();
        assert_eq!(labels, want, "at z = {}", section["z_mm"]);
    }
}

/// The stature is the crown's height above the floor (z = 0), not the body's extent: a sole
/// below the floor (a foot that re-posing swung down with the sole a scanner left it) does not
/// make the body taller.
#[test]
fn the_stature_is_the_crown_above_the_floor() {
    let body = generate(&BodyParams::default()).unwrap();
    let mesh = mesh_of(&body);
    let standing = SegmentedBody::find(&mesh).unwrap().landmarks().height;
    let crown = mesh.bounds().unwrap().max.z;
    assert!((standing - crown).abs() < 1e-9, "{standing} against the crown's {crown}");
    let sunk =
        mesh.map_positions(|p| if p.z < 60.0 && p.x > 0.0 { p - DVec3::Z * 10.0 } else { p });
    let sunk = SegmentedBody::find(&sunk).unwrap().landmarks().height;
    assert!(
        (sunk - standing).abs() < 1e-9,
        "{sunk} with a sole 10 mm below the floor, {standing} standing"
    );
}
