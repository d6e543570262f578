//! Synthetic bodies: generation is deterministic and the landmarks sit where the canonical
//! frame says. (Their surfaces and girths are checked with dressform's own topology and
//! slicer in the root crate's `tests/synthetic_bodies.rs`: `capture-sim` does not depend on
//! dressform.)

use capture_sim::{BodyParams, generate};

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
