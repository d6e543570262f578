//! The MakeHuman assets and posing with the full 163-bone rig (`dressform::pose::makehuman`).

use crate::common;
use dressform::body::mesh::topology;
use dressform::pose::makehuman::{MakeHuman, Pose, Target};
use glam::DVec3;
use std::path::Path;

fn load() -> Option<MakeHuman> {
    let dir = common::makehuman()?;
    Some(MakeHuman::load(&dir).expect("the MakeHuman assets load"))
}

/// The bone and every bone below it in the hierarchy.
fn subtree(mh: &MakeHuman, bone: usize) -> Vec<bool> {
    let mut inside = vec![false; mh.rig.bones.len()];
    for (b, info) in mh.rig.bones.iter().enumerate() {
        inside[b] = b == bone || info.parent.is_some_and(|p| inside[p]);
    }
    inside
}

#[test]
fn the_base_mesh_loads_in_the_canonical_frame() {
    let Some(mh) = load() else { return };
    assert_eq!(mh.base.vertices.len(), 19158);
    assert_eq!(mh.base.skin_vertices.len(), 13380);
    assert_eq!(mh.base.skin_quads.len(), 13378);
    assert_eq!(mh.rig.bones.len(), 163);
    let skin = mh.base.skin(&mh.base.vertices);
    let b = skin.bounds().unwrap();
    // 16.66 dm tall, Z up; facing -Y: the toes reach further forward than the heels back.
    assert!((b.size().z - 1666.0).abs() < 1.0, "height {}", b.size().z);
    assert!(b.size().z > b.size().x && b.size().z > b.size().y);
    let feet: Vec<f64> =
        skin.positions.iter().filter(|p| p.z < b.min.z + 50.0).map(|p| p.y).collect();
    let (toes, heels) = feet.iter().fold((0.0f64, 0.0f64), |(lo, hi), &y| (lo.min(y), hi.max(y)));
    assert!(-toes > heels + 50.0, "toes at y = {toes}, heels at y = {heels}");
    // The `.L` side is +X.
    let wrist = mh.rig.bone_heads(&mh.base.vertices)[mh.rig.bone("wrist.L").unwrap()];
    assert!(wrist.x > 300.0, "{wrist}");
    let topo = topology(&skin);
    assert!(topo.is_closed() && topo.is_manifold() && topo.is_consistently_oriented(), "{topo:?}");
    assert!(skin.signed_volume() > 0.0, "outward-facing");
    assert_eq!(common::largest_mirror_gap(&skin, 0.0), 0.0, "hm08 is exactly mirror-symmetric");
}

#[test]
fn a_weighted_target_moves_its_vertices_by_weight_times_offset() {
    let Some(mh) = load() else { return };
    let name = "measure/measure-waist-circ-incr";
    let target = mh.target(name).unwrap();
    assert!(!target.indices.is_empty());
    let body = mh.shaped(&[(name, 0.5)]).unwrap();
    for (&i, &d) in target.indices.iter().zip(&target.deltas) {
        let moved = body[i as usize] - mh.base.vertices[i as usize];
        assert!((moved - 0.5 * d).length() < 1e-9);
    }
    let moved = (0..body.len()).filter(|&v| body[v] != mh.base.vertices[v]).count();
    assert!(moved <= target.indices.len());
    // A bigger waist: the vertices move away from the body's vertical axis on average.
    let outwards: f64 = target
        .indices
        .iter()
        .zip(&target.deltas)
        .map(|(&i, d)| {
            let p = mh.base.vertices[i as usize];
            DVec3::new(p.x, p.y, 0.0).normalize_or_zero().dot(*d)
        })
        .sum();
    assert!(outwards > 0.0);
}

#[test]
fn a_bad_target_file_is_an_error_naming_the_file_and_line() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("bad.target");
    std::fs::write(&file, "# comment\n1 0.1 0.2 0.3\n99999 0 0 0\n").unwrap();
    let e = Target::load(&file, 19158).unwrap_err().to_string();
    assert!(e.contains("bad.target") && e.contains("line 3") && e.contains("99999"), "{e}");
    std::fs::write(&file, "1 0.1 nan 0.3\n").unwrap();
    let e = Target::load(&file, 19158).unwrap_err().to_string();
    assert!(e.contains("line 1"), "{e}");
    let e = MakeHuman::load(Path::new("/nonexistent")).unwrap_err().to_string();
    assert!(e.contains("base.obj") && e.contains("cannot read"), "{e}");
}

#[test]
fn the_rest_pose_reproduces_the_body_exactly() {
    let Some(mh) = load() else { return };
    let body = mh.shaped(&[("measure/measure-hips-circ-incr", 0.8)]).unwrap();
    assert_eq!(mh.pose(&body, &Pose::rest()).unwrap(), body);
    let moved = mh.pose(&body, &Pose::rest().translate(DVec3::new(1.0, 2.0, 3.0))).unwrap();
    assert!(
        moved.iter().zip(&body).all(|(p, q)| (*p - *q - DVec3::new(1.0, 2.0, 3.0)).length() < 1e-9)
    );
    let e = mh.pose(&body, &Pose::rest().rotate("tail.L", DVec3::X)).unwrap_err().to_string();
    assert!(e.contains("default.mhskel") && e.contains("tail.L"), "{e}");
}

#[test]
fn a_turned_upper_arm_moves_the_arm_and_not_the_torso() {
    let Some(mh) = load() else { return };
    let body = mh.shaped(&[("measure/measure-bust-circ-incr", 0.5)]).unwrap();
    let bone = mh.rig.bone("upperarm01.L").unwrap();
    let theta = DVec3::new(0.0, -0.8, 0.3); // raised sideways and a little forward
    let posed = mh.pose(&body, &Pose::rest().rotate("upperarm01.L", theta)).unwrap();
    // Independent computation: the arm below the shoulder turns rigidly about the shoulder
    // joint (Rodrigues' formula here, quaternions in the library).
    let inside = subtree(&mh, bone);
    let joint = mh.rig.bone_heads(&body)[bone];
    let (axis, angle) = (theta.normalize(), theta.length());
    let rodrigues = |v: DVec3| {
        axis * axis.dot(v) + axis.cross(v).cross(axis) * angle.cos() + axis.cross(v) * angle.sin()
    };
    let (mut rigid, mut still, mut blended) = (0, 0, 0);
    for v in 0..body.len() {
        let share: f64 = mh.weights.of(v).filter(|&(b, _)| inside[b]).map(|(_, w)| w).sum();
        if share >= 1.0 - 1e-12 {
            let expected = joint + rodrigues(body[v] - joint);
            assert!(posed[v].distance(expected) < 1e-9, "vertex {v}");
            rigid += 1;
        } else if share == 0.0 {
            assert_eq!(posed[v], body[v], "vertex {v} has no weight on the arm but moved");
            still += 1;
        } else {
            blended += 1;
        }
    }
    assert!(rigid > 1000 && still > 10000 && blended > 50, "{rigid} {still} {blended}");
    // The hand went up: raised by more than 200 mm.
    let hand = mh.rig.bone_heads(&posed)[mh.rig.bone("wrist.L").unwrap()];
    let rest_hand = mh.rig.bone_heads(&body)[mh.rig.bone("wrist.L").unwrap()];
    assert!(hand.z - rest_hand.z > 200.0, "{rest_hand} -> {hand}");
}

#[test]
fn an_asymmetric_pose_stays_closed_and_manifold() {
    let Some(mh) = load() else { return };
    let body =
        mh.shaped(&[("macrodetails/universal-male-young-averagemuscle-maxweight", 0.7)]).unwrap();
    let pose = Pose::rest()
        .rotate("upperarm01.L", DVec3::new(0.0, -0.9, 0.0))
        .rotate("upperarm01.R", DVec3::new(0.4, 0.2, 0.0))
        .rotate("lowerarm01.R", DVec3::new(-0.9, 0.0, 0.0))
        .rotate("upperleg01.L", DVec3::new(-0.35, 0.0, 0.1))
        .rotate("spine03", DVec3::new(0.0, 0.0, 0.3))
        .rotate("head", DVec3::new(0.2, 0.0, -0.4))
        .translate(DVec3::new(0.0, 0.0, 1000.0));
    let skin = mh.base.skin(&mh.pose(&body, &pose).unwrap());
    let scan =
        dressform::body::scan::from_mesh(skin.clone(), Path::new("posed"), &Default::default())
            .expect("a posed body is a valid scan");
    assert_eq!(scan.cleaning.welded_vertices, 0, "{:?}", scan.cleaning);
    assert_eq!(scan.cleaning.degenerate_triangles, 0, "{:?}", scan.cleaning);
    assert_eq!(scan.body.triangles.len(), skin.triangles.len());
    let topo = topology(&scan.body);
    assert!(topo.is_closed() && topo.is_manifold() && topo.is_consistently_oriented(), "{topo:?}");
    assert!(common::largest_mirror_gap(&skin, 0.0) > 100.0, "the pose is asymmetric");
}
