//! Synthetic bodies: closed, manifold, one piece, and with the requested tape girths on the
//! mesh itself, for random parameter sets and the asymmetric pose.

use crate::section;
use crate::topology;

use rayon::prelude::*;
use sim::capture::{BodyParams, GirthLevel, Pose, SyntheticBody, generate};

use section::tape_girth;
use topology::topology;

/// Relative error of the mesh's tape girth at a truth level against the request.
fn girth_error(body: &SyntheticBody, level: &GirthLevel, requested: f64) -> f64 {
    let (girth, loops) = tape_girth(&body.surface, level.z_mm, level.centre_xy_mm)
        .unwrap_or_else(|| panic!("no torso loop at z = {}", level.z_mm));
    assert!(loops >= 1);
    girth / requested - 1.0
}

/// Signed volume enclosed by the surface (positive when the normals point outward).
fn volume_mm3(s: &sim::capture::TriangleSurface) -> f64 {
    s.triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| s.positions[i as usize]);
            (a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0])
                + a[2] * (b[0] * c[1] - b[1] * c[0]))
                / 6.0
        })
        .sum()
}

fn check_body(name: &str, params: &BodyParams) -> [f64; 3] {
    let body = generate(params).unwrap_or_else(|e| panic!("{name}: {e}"));
    let t = topology(&body.surface);
    assert_eq!(t.bad_edges, 0, "{name}: {t:?}");
    assert_eq!(t.boundary_edges, 0, "{name}: {t:?}");
    assert_eq!(t.non_manifold_vertices, 0, "{name}: {t:?}");
    assert_eq!(t.components, 1, "{name}: {t:?}");
    assert_eq!(t.unused_vertices, 0, "{name}: {t:?}");
    // Genus 0: a sphere.
    assert_eq!(t.euler, 2, "{name}: {t:?}");
    // Outward orientation: positive enclosed volume, of a plausible size (litres).
    let litres = volume_mm3(&body.surface) / 1e6;
    assert!((30.0..250.0).contains(&litres), "{name}: {litres} l");
    let truth = &body.truth;
    let errors = [
        girth_error(&body, &truth.chest, params.chest_girth_mm),
        girth_error(&body, &truth.waist, params.waist_girth_mm),
        girth_error(&body, &truth.hip, params.hip_girth_mm),
    ];
    for (e, level) in errors.iter().zip(["chest", "waist", "hip"]) {
        assert!(e.abs() < 0.003, "{name}: {level} girth off by {:.3}%", e * 100.0);
    }
    // Stature and crotch: the mesh reaches the head top and the floor; truth matches request.
    let (lo, hi) = body.surface.bounds().expect("vertices");
    assert!(lo[2].abs() < 0.5, "{name}: floor at {}", lo[2]);
    assert!((hi[2] - params.height_mm).abs() < 1.0, "{name}: top at {}", hi[2]);
    assert!((truth.crotch_height_mm - params.leg_length_mm).abs() < 0.1);
    assert!((truth.height_mm - params.height_mm).abs() < 0.1);
    errors
}

#[test]
fn twenty_random_bodies_are_closed_manifold_with_requested_girths() {
    let errors: Vec<[f64; 3]> = (0..20u64)
        .into_par_iter()
        .map(|seed| check_body(&format!("seed {seed}"), &BodyParams::random(seed)))
        .collect();
    let max = |l: usize| errors.iter().map(|e| e[l].abs()).fold(0.0, f64::max);
    println!(
        "max |girth error| over 20 bodies: chest {:.4}%, waist {:.4}%, hip {:.4}%",
        100.0 * max(0),
        100.0 * max(1),
        100.0 * max(2)
    );
}

#[test]
fn asymmetric_pose_is_closed_manifold_with_requested_girths() {
    let params = BodyParams { pose: Pose::asymmetric_example(), ..BodyParams::default() };
    check_body("asymmetric", &params);
}

#[test]
fn arms_are_separate_loops_at_the_girth_levels() {
    let body = generate(&BodyParams::default()).expect("default body");
    let truth = &body.truth;
    for level in [&truth.chest, &truth.waist, &truth.hip] {
        let loops = section::section_loops(&body.surface, level.z_mm);
        let torso: Vec<_> =
            loops.iter().filter(|l| section::contains(l, level.centre_xy_mm)).collect();
        assert_eq!(torso.len(), 1, "z = {}", level.z_mm);
        // The torso loop stays within the torso: no point beyond the shoulders' width.
        let half_width = torso[0].iter().map(|p| p[0].abs()).fold(0.0, f64::max);
        assert!(half_width < 0.5 * body.params.shoulder_width_mm, "z = {}", level.z_mm);
    }
    // Chest and waist sections cut both arms (hands hang below the hip in the A-pose).
    assert!(section::section_loops(&body.surface, truth.chest.z_mm).len() >= 3);
    assert!(section::section_loops(&body.surface, truth.waist.z_mm).len() >= 3);
}

#[test]
fn generation_is_deterministic() {
    let params = BodyParams::random(3);
    let a = generate(&params).expect("body");
    let b = generate(&params).expect("body");
    assert_eq!(a, b);
}

#[test]
fn landmarks_sit_where_the_canonical_frame_says() {
    let body = generate(&BodyParams::default()).expect("default body");
    let t = &body.truth;
    let lm = &t.landmarks;
    // Z up: head top at the stature, soles on the floor, crotch at the leg length.
    assert!((lm.head_top[2] - t.height_mm).abs() < 1e-6);
    assert_eq!(lm.left.sole_centre[2], 0.0);
    assert!((lm.crotch[2] - t.crotch_height_mm).abs() < 1e-9);
    // Faces -Y: nose in front of the head top, toes in front of the heels.
    assert!(lm.nose_tip[1] < lm.head_top[1] - 80.0);
    for side in [&lm.left, &lm.right] {
        assert!(side.toe_tip[1] < side.heel[1] - 200.0);
        assert!(side.heel[1] > side.ankle_joint[1]);
        // Levels in order: armpit above the chest, below the acromion.
        assert!(side.armpit[2] > t.chest.z_mm && side.armpit[2] < side.acromion[2]);
        assert!(side.knee_joint[2] < side.hip_joint[2] && side.ankle_joint[2] < side.knee_joint[2]);
    }
    // +X is the subject's left.
    assert!(lm.left.shoulder_joint[0] > 0.0 && lm.right.shoulder_joint[0] < 0.0);
    assert!((t.shoulder_width_mm - body.params.shoulder_width_mm).abs() < 1e-9);
    // Centred: the mid-sagittal plane is x = 0, the waist centre y = 0.
    assert_eq!(t.waist.centre_xy_mm, [0.0, 0.0]);
    assert!(t.chest.z_mm > t.waist.z_mm && t.waist.z_mm > t.hip.z_mm);
    assert!(t.hip.z_mm > t.crotch_height_mm);
    // The surface points outward at the head's top.
    let normals = body.surface.vertex_normals();
    let top = (0..body.surface.positions.len())
        .max_by(|&a, &b| body.surface.positions[a][2].total_cmp(&body.surface.positions[b][2]))
        .expect("vertices");
    assert!(normals[top][2] > 0.95);
}
