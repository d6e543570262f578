//! The statistical body model (`dressform::pose::body_model`, paper 3.1.1): mean value coordinates,
//! skinning, the PCA space, symmetry, the glTF file, the built-in model and the CLI.

use crate::common;
use dressform::body::mesh::{Mesh, topology};
use dressform::pose::body_model::{self, BodyModel, BuildOptions, file, mvc, population, template};
use dressform::pose::makehuman::MakeHuman;
use glam::DVec3;
use std::sync::OnceLock;

fn builtin() -> &'static BodyModel {
    static MODEL: OnceLock<BodyModel> = OnceLock::new();
    MODEL.get_or_init(BodyModel::builtin)
}

/// A closed, non-convex test mesh: a sphere of radius 1 with three deep bulges and dents
/// (a latitude-longitude grid closed by two poles), triangles facing outwards.
fn lumpy_sphere() -> Mesh {
    let (rings, segments) = (24, 36);
    let radius = |t: f64, p: f64| 1.0 + 0.35 * (3.0 * p).sin() * t.sin() * (2.0 * t).cos();
    let point =
        |t: f64, p: f64| DVec3::new(t.sin() * p.cos(), t.sin() * p.sin(), t.cos()) * radius(t, p);
    let mut positions =
        vec![DVec3::Z * radius(0.0, 0.0), -DVec3::Z * radius(std::f64::consts::PI, 0.0)];
    for r in 1..rings {
        let t = std::f64::consts::PI * r as f64 / rings as f64;
        for s in 0..segments {
            positions.push(point(t, std::f64::consts::TAU * s as f64 / segments as f64));
        }
    }
    let at = |r: usize, s: usize| (2 + (r - 1) * segments + s % segments) as u32;
    let mut triangles = Vec::new();
    for s in 0..segments {
        triangles.push([0, at(1, s), at(1, s + 1)]);
        triangles.push([1, at(rings - 1, s + 1), at(rings - 1, s)]);
        for r in 1..rings - 1 {
            triangles.push([at(r, s), at(r + 1, s), at(r + 1, s + 1)]);
            triangles.push([at(r, s), at(r + 1, s + 1), at(r, s + 1)]);
        }
    }
    Mesh::new(positions, triangles)
}

#[test]
fn mean_value_coordinates_reproduce_points_inside_and_outside() {
    let mesh = lumpy_sphere();
    let topo = topology(&mesh);
    assert!(topo.is_closed() && topo.is_consistently_oriented() && mesh.signed_volume() > 0.0);
    let size = mesh.bounds().unwrap().size().length();
    let mut worst: f64 = 0.0;
    let mut negative = false;
    for i in 0..60 {
        let t = i as f64 * 0.7;
        let dir = DVec3::new(t.cos() * (1.3 * t).sin(), t.sin() * (1.3 * t).sin(), (1.3 * t).cos());
        // Inside (0.1-0.6 of the radius) and outside (1.5-3.5 radii).
        for scale in [0.1 + 0.5 * (i % 7) as f64 / 7.0, 1.5 + 2.0 * (i % 5) as f64 / 5.0] {
            let x = dir * scale;
            let w = mvc::coordinates(&mesh, x);
            assert!((w.iter().sum::<f64>() - 1.0).abs() < 1e-12);
            negative |= w.iter().any(|&m| m < 0.0);
            let back: DVec3 = w.iter().zip(&mesh.positions).map(|(m, v)| *m * *v).sum();
            worst = worst.max(back.distance(x) / size);
        }
    }
    assert!(worst < 1e-9, "linear precision: {worst:e} of the size");
    assert!(negative, "outside points and a non-convex mesh give negative weights");
    // A point on a face and one on a vertex.
    let [a, b, c] = mesh.corners(100);
    let on_face = (a + 2.0 * b + c) / 4.0;
    let w = mvc::coordinates(&mesh, on_face);
    let back: DVec3 = w.iter().zip(&mesh.positions).map(|(m, v)| *m * *v).sum();
    assert!(back.distance(on_face) < 1e-12 * size && w.iter().all(|&m| m >= 0.0));
    let w = mvc::coordinates(&mesh, mesh.positions[5]);
    assert_eq!(w[5], 1.0);
}

#[test]
fn the_builtin_model_is_small_symmetric_and_explains_the_population() {
    let m = builtin();
    eprintln!("built-in model: {} bytes", BodyModel::BUILTIN_GLB.len());
    assert!(BodyModel::BUILTIN_GLB.len() <= 4_000_000);
    assert_eq!((m.mean.len(), m.k(), m.skeleton.names.len()), (13380, 15, 21));
    let explained: f64 = m.explained.iter().sum();
    eprintln!("explained variance per component: {:?}; total {explained}", m.explained);
    assert!(explained >= 0.95, "k = 15 explains {explained}");
    assert!(m.explained.windows(2).all(|w| w[0] >= w[1]));
    // Symmetry: the mean and every component map onto themselves (0.01 mm).
    let mean_gap = template::asymmetry(&m.mean, &m.mirror);
    let component_gap =
        m.components.iter().map(|d| template::asymmetry(d, &m.mirror)).fold(0.0, f64::max);
    eprintln!("asymmetry: mean {mean_gap:e} mm, components {component_gap:e} mm per sigma");
    assert!(mean_gap <= 0.01 && component_gap <= 0.01);
    // Skin weights exactly mirror-symmetric, at most 4 bones, summing to 1.
    let bone_mirror = m.skeleton.mirror();
    for v in 0..m.mean.len() {
        let mut own: Vec<(usize, f64)> =
            m.weights.of(v).map(|(b, w)| (bone_mirror[b], w)).collect();
        let mut partner: Vec<(usize, f64)> = m.weights.of(m.mirror[v] as usize).collect();
        own.sort_by_key(|p| p.0);
        partner.sort_by_key(|p| p.0);
        assert_eq!(own, partner, "vertex {v}");
        assert!(own.len() <= 4 && own.iter().map(|p| p.1).sum::<f64>() == 1.0);
    }
    // The template: closed, manifold, outward.
    let topo = topology(&m.mesh(m.mean.clone()));
    assert!(topo.is_closed() && topo.is_manifold() && topo.is_consistently_oriented());
}

/// The bone and its descendants.
fn subtree(m: &BodyModel, bone: usize) -> Vec<bool> {
    let mut inside = vec![false; m.skeleton.names.len()];
    for b in 0..inside.len() {
        inside[b] = b == bone || m.skeleton.parents[b].is_some_and(|p| inside[p]);
    }
    inside
}

#[test]
fn skinning_rest_pose_is_exact_and_one_bone_moves_only_what_it_weighs() {
    let m = builtin();
    let beta = [1.2, -0.7, 0.4, 0.0, 0.9];
    let rest = m.shape(&beta);
    let bones = m.skeleton.names.len();
    assert_eq!(m.posed(&beta, &vec![DVec3::ZERO; bones], DVec3::ZERO), rest);
    let joints = m.joints(&beta);
    let regressed = m.regress_joints(&rest);
    assert!(
        joints.iter().zip(&regressed).all(|(a, b)| a.distance(*b) < 1e-9),
        "joints linear in beta"
    );
    for name in ["lowerleg01.L", "upperarm01.R", "spine03"] {
        let bone = m.skeleton.names.iter().position(|n| n == name).unwrap();
        let mut theta = vec![DVec3::ZERO; bones];
        theta[bone] = DVec3::new(0.5, -0.3, 0.2);
        let posed = m.posed(&beta, &theta, DVec3::ZERO);
        // Independent: Rodrigues' rotation of a rigidly attached vertex about the joint.
        let (axis, angle) = (theta[bone].normalize(), theta[bone].length());
        let turn = |v: DVec3| {
            let r = v - joints[bone];
            joints[bone]
                + r * angle.cos()
                + axis.cross(r) * angle.sin()
                + axis * axis.dot(r) * (1.0 - angle.cos())
        };
        let inside = subtree(m, bone);
        let (mut moved, mut still) = (0, 0);
        for v in 0..rest.len() {
            let share: f64 = m.weights.of(v).filter(|&(b, _)| inside[b]).map(|(_, w)| w).sum();
            if share == 0.0 {
                assert_eq!(posed[v], rest[v], "{name}: vertex {v} has no weight on it but moved");
                still += 1;
            } else {
                let expected = rest[v] + share * (turn(rest[v]) - rest[v]);
                assert!(posed[v].distance(expected) < 1e-9, "{name}: vertex {v}");
                moved += 1;
            }
        }
        assert!(moved > 100 && still > 1000, "{name}: {moved} moved, {still} still");
    }
}

#[test]
fn the_file_round_trips_exactly_and_passes_the_khronos_validator() {
    let m = builtin();
    let bytes = file::to_bytes(m);
    assert_eq!(bytes, BodyModel::BUILTIN_GLB, "read then written: the same bytes");
    let again = file::from_bytes(&bytes).unwrap();
    assert_eq!(&again, m);
    assert_eq!(file::at_file_precision(m.clone()), *m, "idempotent");
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("model.glb");
    file::write(m, &path).unwrap();
    let Some(report) = common::validate_gltf(&path) else { return };
    assert_eq!(report.errors, 0, "{:#}", report.json);
    assert_eq!(report.warnings, 0, "{:#}", report.json);
}

#[test]
fn a_broken_model_file_is_an_error_naming_it() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("broken.glb");
    std::fs::write(&path, &BodyModel::BUILTIN_GLB[..1000]).unwrap();
    let (code, _, err) = common::dressform(&["model", "info", path.to_str().unwrap()]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("broken.glb") && err.lines().count() == 1, "{err}");
}

#[test]
fn mvc_joints_follow_makehumans_joint_rule_on_sampled_bodies() {
    let Some(dir) = common::makehuman() else { return };
    let mh = MakeHuman::load(&dir).unwrap();
    let m = builtin();
    let bodies = population::sample(50, 2024);
    let mut distances = Vec::new();
    for i in 0..50 {
        let full = mh.shaped(&bodies.recipe(i)).unwrap();
        let heads = mh.rig.bone_heads(&full);
        let mvc = m.regress_joints(&mh.base.skin(&full).positions);
        for (n, name) in m.skeleton.names.iter().enumerate() {
            distances.push((mvc[n].distance(heads[mh.rig.bone(name).unwrap()]), name.clone()));
        }
    }
    let mean = distances.iter().map(|d| d.0).sum::<f64>() / distances.len() as f64;
    let worst = distances.iter().max_by(|a, b| a.0.total_cmp(&b.0)).unwrap();
    let mut per_bone: Vec<(String, f64)> = m
        .skeleton
        .names
        .iter()
        .map(|n| {
            (n.clone(), distances.iter().filter(|d| &d.1 == n).map(|d| d.0).fold(0.0, f64::max))
        })
        .collect();
    per_bone.sort_by(|a, b| b.1.total_cmp(&a.1));
    eprintln!(
        "MVC vs MakeHuman joints on 50 bodies: mean {mean:.2} mm, max {:.2} mm ({}); worst bones {:?}",
        worst.0,
        worst.1,
        &per_bone[..5]
    );
    // A few mm on average; the spine joints lie deep inside the torso, where the targets move
    // MakeHuman's joint cubes differently from the skin around them (a belly or buttocks
    // target moves the skin, and so the MVC joint, but not the cube by as much).
    assert!(mean < 5.0 && worst.0 < 40.0);
}

#[test]
fn held_out_bodies_project_onto_the_model_within_millimetres() {
    let Some(dir) = common::makehuman() else { return };
    let mh = MakeHuman::load(&dir).unwrap();
    let m = builtin();
    // Not in the build (another seed), raw (not mirror-averaged).
    let held_out = population::sample(20, 777_777);
    let shaped = (0..20)
        .filter(|&i| held_out.recipe(i).iter().any(|(t, _)| t.starts_with("bodyshapes/")))
        .count();
    assert!(shaped >= 3, "some held-out bodies use bodyshapes/ targets ({shaped})");
    let (mut means, mut maxes) = (Vec::new(), Vec::new());
    for i in 0..20 {
        let body = mh.base.skin(&mh.shaped(&held_out.recipe(i)).unwrap()).positions;
        let (_, back) = m.project(&body);
        let errors: Vec<f64> = body.iter().zip(&back).map(|(a, b)| a.distance(*b)).collect();
        let (v, e) = errors.iter().enumerate().max_by(|a, b| a.1.total_cmp(b.1)).unwrap();
        eprintln!(
            "body {i}: worst vertex {v} at {} off by {e:.1} mm; {:?}",
            body[v],
            held_out
                .recipe(i)
                .iter()
                .filter(|(t, w)| !t.starts_with("macro") && *w > 0.3)
                .collect::<Vec<_>>()
        );
        means.push(errors.iter().sum::<f64>() / errors.len() as f64);
        maxes.push(errors.iter().copied().fold(0.0, f64::max));
    }
    let mean = means.iter().sum::<f64>() / 20.0;
    let worst = maxes.iter().copied().fold(0.0, f64::max);
    eprintln!(
        "held-out projection: mean vertex error {mean:.2} mm (worst body {:.2}), max {worst:.2} mm",
        means.iter().copied().fold(0.0, f64::max)
    );
    // Issue 14: mean <= 5 mm, max <= 15 mm. The held-out bodies come from the build's own
    // distribution (`population`); the largest errors are local details no 15 components hold
    // (a slack belly, pectorals, the corners of MakeHuman's macro blend).
    assert!(mean <= 5.0 && worst <= 15.0, "mean {mean}, max {worst}");
}

#[test]
fn the_builtin_model_rebuilds_from_makehuman_and_reproduces_its_template_joints() {
    let Some(dir) = common::makehuman() else { return };
    let mh = MakeHuman::load(&dir).unwrap();
    let options = BuildOptions::default();
    let rebuilt = body_model::from_makehuman(&mh, &options, &|_, _, _| {}).unwrap();
    // MakeHuman's joint rule on the population's mean body (weights averaged: bodies are linear
    // in them), mirror-averaged; the MVC regressor must give them back on the mean mesh.
    let population = population::sample(options.bodies, options.seed);
    let mean_recipe: Vec<(&str, f64)> = population
        .targets
        .iter()
        .enumerate()
        .map(|(j, t)| {
            (
                t.as_str(),
                population.bodies.iter().map(|b| b[j]).sum::<f64>() / options.bodies as f64,
            )
        })
        .collect();
    let heads = mh.rig.bone_heads(&mh.shaped(&mean_recipe).unwrap());
    let bone_mirror = rebuilt.skeleton.mirror();
    let expected: Vec<DVec3> = (0..rebuilt.skeleton.names.len())
        .map(|n| {
            let own = heads[mh.rig.bone(&rebuilt.skeleton.names[n]).unwrap()];
            let other = heads[mh.rig.bone(&rebuilt.skeleton.names[bone_mirror[n]]).unwrap()];
            (own + template::reflect(other)) / 2.0
        })
        .collect();
    let regressed = rebuilt.regress_joints(&rebuilt.mean);
    let worst = regressed.iter().zip(&expected).map(|(a, b)| a.distance(*b)).fold(0.0, f64::max);
    eprintln!("template joints reproduced within {worst:e} mm");
    assert!(worst < 1e-6, "{worst}");
    // The committed model is this one, as stored.
    let stored = file::at_file_precision(rebuilt);
    let m = builtin();
    let gap =
        |a: &[DVec3], b: &[DVec3]| a.iter().zip(b).map(|(p, q)| p.distance(*q)).fold(0.0, f64::max);
    assert!(gap(&stored.mean, &m.mean) <= 0.001);
    for (a, b) in stored.components.iter().zip(&m.components) {
        assert!(gap(a, b) <= 0.001);
    }
    assert_eq!(
        (&stored.skeleton, &stored.weights, &stored.mirror, &stored.triangles),
        (&m.skeleton, &m.weights, &m.mirror, &m.triangles)
    );
    assert!(
        stored
            .regressor
            .iter()
            .flatten()
            .zip(m.regressor.iter().flatten())
            .all(|(a, b)| (a - b).abs() < 1e-9)
    );
}

#[test]
fn the_cli_builds_describes_and_samples_models() {
    let dir = tempfile::tempdir().unwrap();
    let (code, out, err) = common::dressform(&["model", "info"]);
    assert_eq!(code, 0, "{err}");
    for word in
        ["built-in", "bytes", "bones (21)", "root", "foot.R", "k = 15", "explained", "cumulative"]
    {
        assert!(out.contains(word), "`model info` lacks {word}: {out}");
    }
    // The same as JSON (issue 33), for scripts: its numbers are the table's.
    let (code, json, err) = common::dressform(&["model", "info", "--json"]);
    assert_eq!(code, 0, "{err}");
    let info: serde_json::Value = serde_json::from_str(&json).unwrap();
    assert_eq!(info["file"], "built-in");
    assert_eq!(info["bones"].as_array().unwrap().len(), 21);
    let components = info["components"].as_array().unwrap();
    assert_eq!(components.len(), 15);
    let last = components.last().unwrap()["cumulative"].as_f64().unwrap();
    assert!(last > 0.5 && last <= 1.0 + 1e-9, "{last}");
    let first = &components[0];
    let shown = format!("{:>10.2}", first["sigma_mm"].as_f64().unwrap());
    assert!(out.contains(&shown), "{shown} not in the table: {out}");
    let body = dir.path().join("body.ply");
    let (code, _, err) = common::dressform(&[
        "model",
        "sample",
        "--beta",
        "2,-1.5,0.5",
        "-o",
        body.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    let (mesh, _) = dressform::body::scan::read_mesh(&body).unwrap();
    let expected = builtin().shape(&[2.0, -1.5, 0.5]);
    assert!(mesh.positions.iter().zip(&expected).all(|(a, b)| a.distance(*b) < 1e-9));
    let (code, _, err) =
        common::dressform(&["model", "sample", "--beta", "1,nan", "-o", body.to_str().unwrap()]);
    assert!(code == 2 && err.contains("--beta"), "{err}");
    // The paper's path: registered meshes in the template's topology.
    let meshes = dir.path().join("meshes");
    std::fs::create_dir(&meshes).unwrap();
    let template = dir.path().join("template.glb");
    std::fs::write(&template, BodyModel::BUILTIN_GLB).unwrap();
    let betas: Vec<Vec<f64>> =
        (0..8).map(|i| (0..6).map(|k| ((i * 7 + k * 3) % 5) as f64 - 2.0).collect()).collect();
    for (i, beta) in betas.iter().enumerate() {
        let mesh = builtin().mesh(builtin().shape(beta));
        let bytes = dressform::body::scan::format::Format::Ply.encode(&mesh);
        std::fs::write(meshes.join(format!("body{i}.ply")), bytes).unwrap();
    }
    let out_model = dir.path().join("db.glb");
    let (code, out, err) = common::dressform(&[
        "model",
        "build",
        "--meshes",
        meshes.to_str().unwrap(),
        "--template",
        template.to_str().unwrap(),
        "-o",
        out_model.to_str().unwrap(),
        "--components",
        "6",
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(out.contains("8 bodies"), "{out}");
    let db = file::read(&out_model).unwrap();
    let explained: f64 = db.explained.iter().sum();
    assert!(explained > 0.999, "8 bodies in a 6-dimensional space: {explained}");
    let (_, back) = db.project(&builtin().shape(&betas[3]));
    let err_mm =
        back.iter().zip(builtin().shape(&betas[3])).map(|(a, b)| a.distance(b)).fold(0.0, f64::max);
    // Up to the file's 16-bit components (0.026 mm per sigma, a few sigma here).
    assert!(err_mm < 0.5, "a training mesh projects back: {err_mm} mm");
    if let Some(report) = common::validate_gltf(&out_model) {
        assert_eq!(report.errors, 0, "{:#}", report.json);
    }
    let (code, _, err) = common::dressform(&["model", "build", "-o", out_model.to_str().unwrap()]);
    assert_eq!(code, 2, "{err}");
}
