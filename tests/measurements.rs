//! The measurement set against what the sim generator knows: stature, inside leg and the
//! girths (torso, neck, legs, and the arms across their axes) measured on its implicit surface
//! at the levels the rules chose, the neck base, across shoulder, across back and across
//! front on its implicit surface in the planes and between the landmarks the rules chose, the
//! calf (largest), ankle and underbust girths, the shoulder slopes, the back and front waist
//! lengths along its midline,
//! the shoulder width it was built with and the arm length between its joints; and `measure` on several scans at once,
//! as CSV and JSON with the units in the keys.

use crate::common;

use capture_sim::{BodyParams, SyntheticBody, generate};
use common::{dressform, mesh_of};
use dressform::atomic_output::write_atomically;
use dressform::body::regions::Landmarks;
use dressform::body::scan::format::Format;
use dressform::body::segmented_body::SegmentedBody;
use dressform::body::slice::Contour;
use dressform::shape::measure::{
    ArmMeasures, BodyDimensions, NeckAndShoulders, across_back_and_front, arms, dimensions,
    find_levels, levels, neck_and_shoulders, tape_arc, underbust,
};
use glam::{DVec2, DVec3};
use rayon::prelude::*;

/// Girths against the generator's (mm): ISO 20685-1 allows 4 mm for small girths; the mesh
/// (a 4 mm grid) reads a tape girth within about 1 mm.
const GIRTH_MM: f64 = 2.0;
/// Neck-base girth (mm): taken where the neck flares into the shoulders, the surface's
/// sharpest bend, which the mesh's 4 mm grid rounds most: the mesh read 0.5-3.7 mm over the
/// implicit surface on the six bodies of the test.
const NECK_BASE_MM: f64 = 5.0;
/// Spacing of the levels of the waist lengths' profiles on the implicit surface (mm).
const PROFILE_STEP_MM: f64 = 10.0;
/// Back and front waist length (mm): the rule's profile joins the mesh's sections every 2 mm,
/// the truth the implicit surface's every 10 mm; both follow the same points.
const WAIST_LENGTH_MM: f64 = 3.0;
/// Shoulder slope (degrees): the side of the neck on the mesh's section and on the implicit
/// surface's, to the same shoulder point.
const SLOPE_DEG: f64 = 0.5;
/// Stature and inside leg (mm): the mesh's top and crotch lie within a grid cell's fraction.
const HEIGHT_MM: f64 = 2.0;
/// Shoulder width (mm): the generator's acromion is a design point inside a smooth blend;
/// the shoulder point is the silhouette's corner (see `tests/segmentation.rs`).
const SHOULDER_MM: f64 = 45.0;
/// Arm length (mm): measured from the shoulder point (see [`SHOULDER_MM`]) against the
/// generator's acromion, elbow and wrist joints.
const ARM_LENGTH_MM: f64 = 45.0;
/// How far from the generator's wrist joint the narrowest girth above the hand may lie (mm):
/// the hand's blend (10 mm) thickens the forearm's end, so the narrowest level is just above.
const WRIST_JOINT_MM: f64 = 30.0;

/// The neck's and shoulders' measurements on the generator's implicit surface, in the planes
/// and between the landmarks the rules chose on the mesh: (neck base, across shoulder, across
/// back, across front).
fn upper_torso_truth(body: &SyntheticBody, u: &NeckAndShoulders, m: &Landmarks) -> [f64; 4] {
    let neck = &u.neck_base;
    let neck_base =
        body.girth_across(neck.origin.to_array(), neck.normal.to_array()).expect("inside the neck");
    // The arc over the shoulders, in the plane's own coordinates.
    let over = &u.across_shoulder;
    let (e1, e2) = (
        over.normal.any_orthonormal_vector(),
        over.normal.cross(over.normal.any_orthonormal_vector()),
    );
    let flat = |p: DVec3| DVec2::new((p - over.origin).dot(e1), (p - over.origin).dot(e2));
    let points = body
        .section_across(over.origin.to_array(), over.normal.to_array())
        .expect("inside the shoulders");
    let loop_ =
        Contour { points: points.into_iter().map(|p| flat(DVec3::from_array(p))).collect() };
    let (lsp, rsp) = (m.left_armhole.shoulder_point, m.right_armhole.shoulder_point);
    let across_shoulder = tape_arc(&loop_, flat(lsp), flat(rsp), flat(u.back_neck_point));
    // Across back and front: the horizontal section, clipped by the mesh's arm plates.
    let z = u.across_level;
    let centre = body.torso_centre_at(z);
    let points =
        body.section_across([centre[0], centre[1], z], [0.0, 0.0, 1.0]).expect("inside the torso");
    let section = Contour { points: points.into_iter().map(|p| DVec2::new(p[0], p[1])).collect() };
    let torso = m.right_armhole.clip(&m.left_armhole.clip(&section, z), z);
    let (back, front) = across_back_and_front(&torso, z, [&m.left_armhole, &m.right_armhole]);
    [neck_base, across_shoulder, back, front]
}

/// The length of the torso's front (`front`) or back midline profile on the generator's
/// implicit surface from the waist level `from` up to the neck level `to`: at each level the
/// front- or back-most point within the rule's band of the centre line, levels
/// [`PROFILE_STEP_MM`] apart (a smooth profile: finer steps change the length by far less
/// than the tolerance).
fn midline_truth(body: &SyntheticBody, centre_x: f64, from: f64, to: f64, front: bool) -> f64 {
    let count = ((to - from) / PROFILE_STEP_MM).ceil() as usize;
    let sign = if front { -1.0 } else { 1.0 };
    let profile: Vec<DVec2> = (0..=count)
        .map(|k| {
            let z = from + (to - from) * k as f64 / count as f64;
            let c = body.torso_centre_at(z);
            let points =
                body.section_across([c[0], c[1], z], [0.0, 0.0, 1.0]).expect("inside the torso");
            let y = (points.iter())
                .filter(|p| (p[0] - centre_x).abs() <= dressform::shape::measure::MIDLINE_BAND_MM)
                .map(|p| sign * p[1])
                .fold(f64::NEG_INFINITY, f64::max);
            DVec2::new(sign * y, z)
        })
        .collect();
    profile.windows(2).map(|w| w[0].distance(w[1])).sum()
}

/// The largest girth of a leg on the implicit surface between `lo` and `hi`: every 10 mm, then
/// every 2 mm (the rule's step) around the largest.
fn calf_truth(leg: &dyn Fn(f64) -> f64, lo: f64, hi: f64) -> f64 {
    let best = |zs: Vec<f64>| {
        zs.into_iter().map(|z| (leg(z), z)).max_by(|a, b| a.0.total_cmp(&b.0)).expect("levels")
    };
    let coarse = best((0..).map(|k| lo + 10.0 * k as f64).take_while(|&z| z <= hi).collect());
    best((-5..=5).map(|k| (coarse.1 + 2.0 * k as f64).clamp(lo, hi)).collect()).0
}

/// (name, measured, known) for one body.
fn compare(
    body: &SyntheticBody,
    d: &BodyDimensions,
    arm: &[Option<ArmMeasures>; 2],
    crotch: f64,
    neck: f64,
    upper: (&NeckAndShoulders, &Landmarks),
    under_z: f64,
) -> Vec<(String, f64, f64)> {
    let t = &body.truth;
    let torso = |z: f64| body.girth_around(body.torso_centre_at(z), z).expect("inside the torso");
    let leg = |left: bool, z: f64| {
        body.girth_around(body.leg_axis_at(left, z), z).expect("inside the leg")
    };
    let h = t.height_mm;
    let thigh_z = crotch - dressform::shape::measure::THIGH_BELOW_CROTCH * h;
    let knee_z = dressform::shape::measure::KNEE_OF_CROTCH * crotch;
    let mut rows = vec![
        ("stature".to_string(), d.stature_mm, h),
        ("inside leg".into(), d.inside_leg_mm, t.crotch_height_mm),
        ("chest".into(), d.chest_girth_mm, t.chest.tape_girth_mm),
        ("waist".into(), d.waist_girth_mm, t.waist.tape_girth_mm),
        ("hip".into(), d.hip_girth_mm, t.hip.tape_girth_mm),
        (
            "high hip".into(),
            d.high_hip_girth_mm,
            torso(0.5 * (d.waist_height_mm + d.hip_height_mm)),
        ),
        ("neck".into(), d.neck_girth_mm, torso(neck)),
        ("shoulder width".into(), d.shoulder_width_mm, t.shoulder_width_mm),
    ];
    let [neck_base, across_shoulder, across_back, across_front] =
        upper_torso_truth(body, upper.0, upper.1);
    rows.push(("neck base".into(), d.neck_base_girth_mm, neck_base));
    rows.push(("across shoulder".into(), d.across_shoulder_mm, across_shoulder));
    rows.push(("across back".into(), d.across_back_mm, across_back));
    rows.push(("across front".into(), d.across_front_mm, across_front));
    let m = upper.1;
    // The underbust where the rule found it; the shoulder slope from the side of the implicit
    // neck at the neck level to the shoulder points the rule found.
    rows.push(("underbust".into(), d.underbust_girth_mm, torso(under_z)));
    let c = body.torso_centre_at(neck);
    let neck_loop =
        body.section_across([c[0], c[1], neck], [0.0, 0.0, 1.0]).expect("inside the neck");
    for (side, name, armhole, slope) in [
        (1.0, "left", &m.left_armhole, d.shoulder_slope_deg.left),
        (-1.0, "right", &m.right_armhole, d.shoulder_slope_deg.right),
    ] {
        let outer = (neck_loop.iter().map(|p| DVec3::from_array(*p)))
            .max_by(|a, b| (side * a.x).total_cmp(&(side * b.x)))
            .expect("a neck loop");
        let point = armhole.shoulder_point;
        let run = (point.truncate() - outer.truncate()).length();
        rows.push((
            format!("{name} shoulder slope"),
            slope,
            ((outer.z - point.z) / run).atan().to_degrees(),
        ));
    }
    for (front, name, value) in [
        (false, "back waist length", d.back_waist_length_mm),
        (true, "front waist length", d.front_waist_length_mm),
    ] {
        rows.push((
            name.into(),
            value,
            midline_truth(body, m.centre_x, d.waist_height_mm, neck, front),
        ));
    }
    for (left, name) in [(true, "left"), (false, "right")] {
        let pick = |b: &dressform::shape::measure::Bilateral| if left { b.left } else { b.right };
        rows.push((format!("{name} thigh"), pick(&d.thigh_girth_mm), leg(left, thigh_z)));
        rows.push((format!("{name} knee"), pick(&d.knee_girth_mm), leg(left, knee_z)));
        rows.push((format!("{name} ankle"), pick(&d.ankle_girth_mm), leg(left, m.ankle)));
        let calf = calf_truth(&|z| leg(left, z), m.ankle, knee_z);
        rows.push((format!("{name} calf"), pick(&d.calf_girth_mm), calf));
        // Arms: the girths across the axis where the rules took them, on the implicit
        // surface; the length against the generator's joints (shoulder point to elbow to wrist).
        let a = arm[usize::from(!left)].as_ref().expect("an A-posed arm is measured");
        let across = |s: &dressform::shape::measure::ArmSection| {
            body.girth_across(s.centre.to_array(), s.axis.to_array()).expect("inside the arm")
        };
        rows.push((format!("{name} upper arm"), pick(&d.upper_arm_girth_mm), across(&a.upper_arm)));
        rows.push((format!("{name} wrist"), pick(&d.wrist_girth_mm), across(&a.wrist)));
        let side = if left { &t.landmarks.left } else { &t.landmarks.right };
        let [acromion, elbow, wrist] =
            [side.acromion, side.elbow_joint, side.wrist_joint].map(glam::DVec3::from_array);
        let length = acromion.distance(elbow) + elbow.distance(wrist);
        rows.push((format!("{name} arm length"), pick(&d.arm_length_mm), length));
        // The wrist rule finds the wrist: its axis point near the generator's wrist joint.
        let wrist_gap = a.wrist.centre.distance(wrist);
        assert!(wrist_gap < WRIST_JOINT_MM, "{name} wrist taken {wrist_gap:.0} mm from the joint");
    }
    rows
}

#[test]
fn the_measurement_set_matches_what_the_generator_knows() {
    let seeds: Vec<u64> = (0..6).collect();
    let rows: Vec<(u64, String, f64, f64)> = seeds
        .par_iter()
        .flat_map(|&seed| {
            let body = generate(&BodyParams::random(seed)).unwrap();
            let mesh = mesh_of(&body);
            let segmented = SegmentedBody::find(&mesh).unwrap();
            let lv = levels(&segmented);
            let d = dimensions(&segmented, &lv);
            let m = segmented.landmarks();
            // Bilateral values of a body standing symmetrically agree side to side.
            for b in [d.thigh_girth_mm, d.knee_girth_mm, d.calf_girth_mm, d.ankle_girth_mm] {
                assert!((b.left - b.right - b.difference).abs() < 1e-9);
                assert!(b.left > 100.0 && b.right > 100.0, "seed {seed}: {b:?}");
            }
            assert!(d.calf_girth_mm.left > d.ankle_girth_mm.left);
            assert!(d.underbust_girth_mm < d.chest_girth_mm, "seed {seed}");
            for s in [d.shoulder_slope_deg.left, d.shoulder_slope_deg.right] {
                assert!((5.0..40.0).contains(&s), "seed {seed}: shoulder slope {s}");
            }
            let waist_length = [d.back_waist_length_mm, d.front_waist_length_mm];
            for w in waist_length {
                // Neck to waist: longer than the straight rise, shorter than half the stature.
                assert!(w > m.neck - lv.waist && w < 0.5 * m.height, "seed {seed}: {w}");
            }
            let upper = neck_and_shoulders(&segmented).expect("the neck and shoulders are found");
            let under_z = underbust(&segmented, &lv).expect("an underbust").z;
            compare(&body, &d, &arms(&segmented), m.crotch, m.neck, (&upper, m), under_z)
                .into_iter()
                .map(|(n, a, b)| (seed, n, a, b))
                .collect::<Vec<_>>()
        })
        .collect();
    let mut worst: std::collections::BTreeMap<String, (f64, u64)> = Default::default();
    for (seed, name, measured, known) in &rows {
        let key = name.trim_start_matches("left ").trim_start_matches("right ").to_string();
        let e = worst.entry(key).or_insert((0.0, 0));
        if (measured - known).abs() > e.0.abs() {
            *e = (measured - known, *seed);
        }
    }
    for (name, (error, seed)) in &worst {
        let unit = if name.ends_with("slope") { "deg" } else { "mm" };
        println!("{name:<18} worst {error:+7.2} {unit} (seed {seed})");
    }
    for (seed, name, measured, known) in &rows {
        let tolerance = match name.trim_start_matches("left ").trim_start_matches("right ") {
            "stature" | "inside leg" => HEIGHT_MM,
            "shoulder width" => SHOULDER_MM,
            "arm length" => ARM_LENGTH_MM,
            "neck base" => NECK_BASE_MM,
            "back waist length" | "front waist length" => WAIST_LENGTH_MM,
            "shoulder slope" => SLOPE_DEG,
            _ => GIRTH_MM,
        };
        assert!(
            (measured - known).abs() <= tolerance,
            "seed {seed}: {name} {measured:.1} mm, the generator's {known:.1} mm"
        );
    }
}

#[test]
fn several_scans_measure_in_parallel_as_csv_and_json() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("scans");
    std::fs::create_dir(&dir).unwrap();
    for seed in [1, 2] {
        let body = generate(&BodyParams::random(seed)).unwrap();
        write_atomically(
            &dir.join(format!("customer{seed}.ply")),
            &Format::Ply.encode(&mesh_of(&body)),
        )
        .unwrap();
    }
    let single = tmp.path().join("one.obj");
    let body = generate(&BodyParams::default()).unwrap();
    write_atomically(&single, &Format::Obj.encode(&mesh_of(&body))).unwrap();
    let (d, s) = (dir.to_str().unwrap(), single.to_str().unwrap());

    let (code, stdout, stderr) = dressform(&["measure", s, d, "--csv"]);
    assert_eq!(code, 0, "{stderr}");
    let lines: Vec<&str> = stdout.lines().collect();
    assert_eq!(lines.len(), 4, "a header and one row per scan: {stdout}");
    let header: Vec<&str> = lines[0].split(',').collect();
    assert_eq!(header[0], "file");
    for key in ["stature_mm", "chest_girth_mm", "thigh_girth_mm.left", "shoulder_slope_deg.right"] {
        assert!(header.contains(&key), "{key} in {header:?}");
    }
    for row in &lines[1..] {
        assert_eq!(row.split(',').count(), header.len(), "{row}");
    }
    assert!(lines[1].contains("one.obj") && lines[2].contains("customer1.ply"));

    let (code, stdout, stderr) = dressform(&["measure", d, "--json"]);
    assert_eq!(code, 0, "{stderr}");
    let v: serde_json::Value = serde_json::from_str(&stdout).unwrap();
    let all = v.as_array().expect("an array for several scans");
    assert_eq!(all.len(), 2);
    // Every number's key names its unit.
    fn check_units(v: &serde_json::Value, key: &str) {
        match v {
            serde_json::Value::Object(map) => {
                for (k, v) in map {
                    let unitless =
                        ["normal", "left", "right", "difference", "at", "warnings", "file"];
                    let named =
                        k.ends_with("_mm") || k.ends_with("_deg") || unitless.contains(&k.as_str());
                    assert!(named || !v.is_number(), "{key}.{k} has no unit");
                    check_units(v, if named { k } else { key });
                }
            }
            serde_json::Value::Array(items) => items.iter().for_each(|i| check_units(i, key)),
            _ => {}
        }
    }
    check_units(&all[0], "");

    // One scan that fails does not stop the others, and sets the exit status.
    let broken = tmp.path().join("broken.ply");
    std::fs::write(&broken, b"ply\nnot a mesh").unwrap();
    let (code, stdout, stderr) = dressform(&["measure", broken.to_str().unwrap(), s, "--csv"]);
    assert_eq!(code, 2, "{stderr}");
    assert!(stderr.contains("broken.ply"), "{stderr}");
    assert_eq!(stdout.lines().count(), 2, "the good scan is still measured: {stdout}");
}

/// A level its rule cannot find on the body is reported, not passed off as found: a barrel
/// torso (waist wider than chest and hip) has no narrowest level inside the waist's band, so
/// the waist falls back to its proportion with a note; the same body with a waist has none.
#[test]
fn a_level_taken_from_a_proportion_is_reported() {
    let shaped = BodyParams::default();
    let barrel = BodyParams { waist_girth_mm: 1.12 * shaped.chest_girth_mm, ..shaped.clone() };
    assert!(barrel.waist_girth_mm > barrel.hip_girth_mm, "a barrel: {barrel:?}");
    let notes = |p: &BodyParams| {
        let mesh = mesh_of(&generate(p).unwrap());
        find_levels(&SegmentedBody::find(&mesh).unwrap()).fallbacks
    };
    let (with_waist, without) = (notes(&shaped), notes(&barrel));
    println!("shaped: {with_waist:?}\nbarrel: {without:?}");
    assert!(with_waist.is_empty(), "{with_waist:?}");
    assert!(
        without.iter().any(|n| n.contains("waist level was not found")),
        "no note for the barrel's waist: {without:?}"
    );
}

/// The MakeHuman base body's chest level lies at its armpits, above the bust, where the front
/// is set farther back than anywhere below: the underbust is still the fold under the bust,
/// smaller than the chest (it used to be the chest level itself, 850.8 mm both).
#[test]
fn the_underbust_is_the_fold_under_the_bust_even_below_a_chest_level_at_the_armpits() {
    let Some(dir) = common::makehuman() else { return };
    let scan = dressform::body::scan::load(&dir.join("base.obj"), &Default::default()).unwrap();
    let segmented = SegmentedBody::find(&scan.body).unwrap();
    let d = dimensions(&segmented, &levels(&segmented));
    eprintln!("chest {:.1} mm, underbust {:.1} mm", d.chest_girth_mm, d.underbust_girth_mm);
    assert!(d.underbust_girth_mm < d.chest_girth_mm, "{d:?}");
}
