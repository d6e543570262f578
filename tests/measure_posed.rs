//! Issue 33: measurements that hold on posed scans. ISO 8559-1's chest girth at the fullest
//! level under the armpits (checked against sections cut by another path, on MakeHuman's
//! bodies); a waist level outside the torso's narrowest region held back with its reason (a
//! trunk whose narrowest level lies beyond the waist's band, as issue 33's "112 mm below"); a
//! stance that moves a level named, with `reconstruct`; `symmetrize` failing on a stance it
//! cannot take apart names `reconstruct`, which takes it.

use std::path::Path;

use crate::common::{self, dressform, makehuman_scan::girths, makehuman_scan::write_obj, mesh_of};
use capture_sim::{BodyParams, generate};
use dressform::body::mesh::Mesh;
use dressform::body::scan::{self, Scan, frame::FrameOptions};
use dressform::body::segmented_body::SegmentedBody;
use dressform::pose::body_model::population;
use dressform::pose::makehuman::{MakeHuman, Pose};
use dressform::shape::measure::{
    CHEST_TAPE_BELOW_ARMPIT_MM, MeasureReport, find_levels, measure_scan,
};
use glam::DVec3;
use rayon::prelude::*;

/// MakeHuman bodies whose chest is checked.
const BODIES: usize = 8;
/// How far the chest girth may read under the fullest section the test cuts (mm): the rule
/// samples every 2 mm or less, the test every 1 mm, and near the top of the band the girth
/// grows up to 4 mm per mm of height.
const SAMPLING_MM: f64 = 4.0;

fn measured(mesh: Mesh) -> MeasureReport {
    measure_scan(&scanned(mesh), &[]).unwrap()
}

/// `mesh` read as a scan: in the canonical frame.
fn scanned(mesh: Mesh) -> Scan {
    scan::from_mesh(mesh, Path::new("customer"), &FrameOptions::default()).unwrap()
}

/// Body `i` of a MakeHuman population, in `pose`.
fn makehuman_body(mh: &MakeHuman, i: usize, pose: &Pose) -> Mesh {
    let population = population::sample(BODIES, 33);
    let shaped = mh.shaped(&population.recipe(i)).unwrap();
    mh.base.skin(&mh.pose(&shaped, pose).unwrap())
}

/// The chest girth is the fullest girth under the armpits: no section the test cuts between
/// 10% of the stature below the lower armpit and [`CHEST_TAPE_BELOW_ARMPIT_MM`] below it is
/// fuller, and it is never smaller than the bust girth. Printed: how far below that level the
/// bust level lies and how much the bust girth reads less (issue 33: 8-58 mm, 6-124 mm).
#[test]
fn the_chest_girth_is_the_fullest_under_the_armpits() {
    let Some(dir) = common::makehuman() else { return };
    let mh = MakeHuman::load(&dir).unwrap();
    let rows: Vec<String> = (0..BODIES)
        .into_par_iter()
        .map(|i| {
            let scan = scanned(makehuman_body(&mh, i, &Pose::rest()));
            let m = measure_scan(&scan, &[]).unwrap();
            let (d, lm) = (&m.dimensions, &m.landmarks);
            let armpit = lm.left_armpit.min(lm.right_armpit);
            let (lo, hi) = (armpit - 0.1 * lm.height, armpit - CHEST_TAPE_BELOW_ARMPIT_MM);
            assert!(
                (lo - 1.0..=hi + 1.0).contains(&d.chest_height_mm)
                    || (d.chest_height_mm - m.levels.chest).abs() < 1.0,
                "body {i}: chest at {:.0} mm, the band {lo:.0}-{hi:.0} mm",
                d.chest_height_mm
            );
            let zs: Vec<f64> = (0..).map(|k| lo + k as f64).take_while(|z| *z <= hi).collect();
            let cut = girths(&scan.body, lm.centre_x, &zs);
            let (k, fullest) = cut
                .iter()
                .copied()
                .enumerate()
                .filter(|(_, g)| g.is_finite())
                .max_by(|a, b| a.1.total_cmp(&b.1))
                .unwrap();
            assert!(
                d.chest_girth_mm >= fullest - SAMPLING_MM,
                "body {i}: chest {:.1} mm at {:.0}, a fuller section {fullest:.1} mm at {:.0}",
                d.chest_girth_mm,
                d.chest_height_mm,
                zs[k]
            );
            assert!(d.chest_girth_mm >= d.bust_girth_mm, "body {i}: {d:?}");
            format!(
                "body {i}: chest {:.1} mm at {:.0} ({:.0} under the armpit), bust {:.1} mm at {:.0} \
                 ({:.0} lower, {:.1} mm less); fullest cut {fullest:.1} mm",
                d.chest_girth_mm,
                d.chest_height_mm,
                armpit - d.chest_height_mm,
                d.bust_girth_mm,
                m.levels.chest,
                d.chest_height_mm - m.levels.chest,
                d.chest_girth_mm - d.bust_girth_mm
            )
        })
        .collect();
    for row in rows {
        println!("{row}");
    }
}

/// A flat-chested customer whose trunk is pinched on one side above the waist's band (at 88% of
/// the way from the hip to the chest): the torso's narrowest level lies there, beyond the band
/// the waist's rule searches, and the waist it finds is larger by more than
/// `WAIST_OVER_NARROWEST_MM`. The waist and what hangs on its level are held back as `null`
/// with the reason naming the narrowest level; the same body unpinched keeps its waist.
#[test]
fn a_waist_level_outside_the_narrowest_region_is_held_back() {
    // A trunk with a moderate waist (85% of the chest): pinched, it is narrower there.
    let shaped = BodyParams::default();
    let params = BodyParams {
        bust_prominence: 0.0,
        resolution_mm: 6.0,
        waist_girth_mm: 0.85 * shaped.chest_girth_mm,
        ..shaped
    };
    let body = mesh_of(&generate(&params).unwrap());
    let plain = measured(body.clone());
    assert!(plain.dimensions.waist_girth_mm.is_finite(), "{:?}", plain.unreliable);
    let segmented = SegmentedBody::find(&body).unwrap();
    let levels = find_levels(&segmented).levels;
    let lm = segmented.landmarks();
    let at = levels.hip + 0.88 * (levels.chest - levels.hip);
    // How much of its half-width the pinched side loses at `at` (a Gaussian 25 mm wide).
    const PINCH: f64 = 0.5;
    // The body's own frame is the scan's here (the generator stands it on the floor, Z up).
    let half_width = 0.5 * params.shoulder_width_mm;
    let pinched = body.map_positions(|p| {
        let out = p.x - lm.centre_x;
        if out <= 0.0 || out > half_width {
            return p;
        }
        let along = (-((p.z - at) / 25.0).powi(2)).exp();
        DVec3::new(lm.centre_x + out * (1.0 - PINCH * along), p.y, p.z)
    });
    let m = measured(pinched);
    let json = serde_json::to_value(&m).unwrap();
    println!("warnings: {:#?}", m.warnings);
    for name in ["waist_girth_mm", "waist_height_mm", "high_hip_girth_mm", "back_waist_length_mm"] {
        assert!(json["dimensions"][name].is_null(), "{name}: {}", json["dimensions"][name]);
        let held = m.unreliable.iter().find(|u| u.measurement == name).expect(name);
        assert!(held.reason.contains("the torso's narrowest level"), "{}", held.reason);
    }
    assert!(json["measurements"]["waist"]["tape_mm"].is_null());
    assert!(m.warnings.iter().any(|w| w.contains("waist_girth_mm") && w.contains("mm below")));
    let waist = m.unreliable.iter().find(|u| u.measurement == "waist_girth_mm").unwrap();
    assert!(waist.value > plain.dimensions.waist_girth_mm - 5.0, "the rule's level: {waist:?}");
}

/// A slightly posed body (one arm 15 degrees further out, the spine bent 4 degrees) is measured
/// with a warning that its stance moves the chest level and names `reconstruct`; the same body
/// standing symmetric has no such warning.
#[test]
fn measure_says_when_the_stance_moves_a_measurement() {
    let Some(dir) = common::makehuman() else { return };
    let mh = MakeHuman::load(&dir).unwrap();
    let posed = Pose::rest()
        .rotate("upperarm01.L", DVec3::Y * -(15f64.to_radians()))
        .rotate("spine03", DVec3::Y * 2f64.to_radians())
        .rotate("spine02", DVec3::Y * 2f64.to_radians());
    let stance = |pose: &Pose| {
        let m = measured(makehuman_body(&mh, 0, pose));
        m.warnings.into_iter().filter(|w| w.contains("stand")).collect::<Vec<_>>()
    };
    assert!(stance(&Pose::rest()).is_empty());
    let warned = stance(&posed);
    println!("{warned:#?}");
    assert!(
        warned.iter().any(|w| w.contains("armpits stand")
            && w.contains("chest and bust levels")
            && w.contains("`dressform reconstruct`")),
        "{warned:?}"
    );
}

/// Arms raised above the shoulders (a Y stance): `symmetrize` cannot find the armpits, and its
/// one-line error says that `reconstruct` re-poses such a scan; `reconstruct` takes it.
#[test]
fn symmetrize_failing_on_a_stance_names_reconstruct() {
    let Some(dir) = common::makehuman() else { return };
    let mh = MakeHuman::load(&dir).unwrap();
    let raised = Pose::rest()
        .rotate("upperarm01.L", DVec3::Y * -(90f64.to_radians()))
        .rotate("upperarm01.R", DVec3::Y * 90f64.to_radians());
    let tmp = tempfile::tempdir().unwrap();
    let scan = tmp.path().join("raised.obj");
    write_obj(&mh.base.skin(&mh.pose(&mh.shaped(&[]).unwrap(), &raised).unwrap()), &scan);
    let (scan, out) = (scan.to_str().unwrap(), tmp.path().join("out"));
    let (code, _, stderr) = dressform(&["symmetrize", scan, "-o", out.to_str().unwrap()]);
    assert_eq!(code, 2, "{stderr}");
    assert_eq!(stderr.trim().lines().count(), 1, "{stderr}");
    assert!(stderr.contains("raised.obj: no "), "{stderr}");
    assert!(stderr.contains("`dressform reconstruct` re-poses a scan in any other stance"));
    assert!(!stderr.contains("more characters"), "{stderr}");
    let (code, _, stderr) = dressform(&["reconstruct", scan, "-o", out.to_str().unwrap()]);
    assert_eq!(code, 0, "{stderr}");
}
