//! Fitting the reference form to synthetic customers: inside the form's range every ring's girth
//! matches the mannequin's within 2 mm with identical left/right set-points; beyond it, the
//! saturated rings and their excess are reported and no set-point leaves its stroke.

use capture_sim::{BodyParams, generate};
use dressform::body::mesh::Mesh;
use dressform::body::scan::{self, frame::FrameOptions};
use dressform::form::form_fit::fit;
use dressform::run::pipeline::symmetrize;
use dressform::shape::mannequin::MannequinOptions;
use dressform::shape::profiles::Profiles;
use form_description::reference;
use glam::DVec3;
use std::path::Path;

fn profiles_of(params: &BodyParams) -> Profiles {
    let body = generate(params).unwrap();
    let mesh = Mesh::new(
        body.surface.positions.iter().map(|&p| DVec3::from_array(p)).collect(),
        body.surface.triangles,
    );
    let scan = scan::from_mesh(mesh, Path::new("customer"), &FrameOptions::default()).unwrap();
    let out = symmetrize(&scan, &MannequinOptions::default(), |_| {}).unwrap();
    Profiles::of(&out.mannequin, &out.comparison.levels)
}

fn assert_within_strokes(fit: &dressform::form::form_fit::FormFit) {
    let form = reference();
    for a in &form.actuators {
        let e = fit.positions_mm[&a.id];
        assert!((0.0..=a.stroke_mm).contains(&e), "{} at {e} outside 0..={}", a.id, a.stroke_mm);
        if let Some(m) = form.mirror_of(&a.id) {
            assert_eq!(e, fit.positions_mm[&m.id], "{} and its mirror {}", a.id, m.id);
        }
    }
}

#[test]
fn customers_inside_the_range_are_matched_within_2_mm_at_every_ring() {
    for params in [
        BodyParams::default(),
        BodyParams { height_mm: 1640.0, leg_length_mm: 760.0, ..BodyParams::default() },
    ] {
        let fit = fit(&profiles_of(&params), &reference()).unwrap();
        assert_within_strokes(&fit);
        for ring in &fit.rings {
            assert!(
                ring.mannequin_girth_mm > 0.0,
                "{}: the mannequin has a section there",
                ring.ring
            );
            assert!(
                (ring.form_girth_mm - ring.mannequin_girth_mm).abs() <= 2.0,
                "{}: form {:.1} vs mannequin {:.1}",
                ring.ring,
                ring.form_girth_mm,
                ring.mannequin_girth_mm
            );
            // The girth is met; where the section's shape differs from the ring's panel layout
            // (a flat back, a slim abdomen in a deep ring), a panel rests off the mannequin by a
            // few millimetres, and the report says where.
            assert!(
                ring.largest_radial_gap_mm < 15.0,
                "{}: gap {:.1}",
                ring.ring,
                ring.largest_radial_gap_mm
            );
        }
        // Anchored rings sit on their levels: chest, waist, hip at offset 0 from their level.
        for name in ["chest", "waist", "hip"] {
            let ring = fit.rings.iter().find(|r| r.ring == name).unwrap();
            assert!(ring.anchor.is_some());
        }
    }
}

#[test]
fn a_customer_beyond_the_forms_range_is_reported_and_clamped() {
    let big = BodyParams {
        chest_girth_mm: 1450.0,
        waist_girth_mm: 1350.0,
        hip_girth_mm: 1550.0,
        height_mm: 1800.0,
        leg_length_mm: 820.0,
        shoulder_width_mm: 440.0,
        pose: capture_sim::Pose {
            left_arm: arm(70.0),
            right_arm: arm(70.0),
            ..capture_sim::Pose::a_pose()
        },
        ..BodyParams::default()
    };
    let fit = fit(&profiles_of(&big), &reference()).unwrap();
    assert_within_strokes(&fit);
    let saturated: Vec<&str> = fit.saturated().map(|r| r.ring.as_str()).collect();
    for ring in ["waist", "hip"] {
        assert!(saturated.contains(&ring), "{ring} saturates: {saturated:?}");
    }
    let hip = fit.rings.iter().find(|r| r.ring == "hip").unwrap();
    assert!(
        hip.mannequin_girth_mm - hip.form_girth_mm > 10.0,
        "the shortfall is reported in the girths"
    );
    assert!(hip.saturated.iter().any(|s| s.beyond_mm > 0.0), "{:?}", hip.saturated);
}

fn arm(abduction: f64) -> capture_sim::ArmPose {
    capture_sim::ArmPose { abduction_deg: abduction, ..capture_sim::Pose::a_pose().left_arm }
}
