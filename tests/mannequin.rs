//! The symmetric mannequin of the MakeHuman body (already symmetric): girths unchanged within
//! 1 mm, the torso within 2 mm of the input surface, a closed, manifold, consistently oriented
//! mesh; and the `symmetrize`, `measure` and `slice` commands with their error paths.

use crate::common;

use common::{SurfaceDistance, dressform, largest_mirror_gap, makehuman};
use dressform::body::mesh::topology;
use dressform::body::scan::{self, frame::FrameOptions};
use dressform::run::pipeline::symmetrize;
use dressform::shape::mannequin::MannequinOptions;
use dressform::shape::symmetry::Preserve;
use glam::DVec3;
use std::path::Path;

#[test]
fn makehuman_mannequin_keeps_girths_and_surface() {
    let Some(dir) = makehuman() else { return };
    let scan = scan::load(&dir.join("base.obj"), &FrameOptions::default()).unwrap();
    for preserve in [Preserve::Tape, Preserve::Contour] {
        let options = MannequinOptions { preserve, ..Default::default() };
        let out = symmetrize(&scan, &options, |_| {}).unwrap();
        let m = &out.mannequin;

        let t = topology(&m.mesh);
        assert!(
            t.is_closed() && t.is_manifold() && t.is_consistently_oriented(),
            "{preserve:?}: {t:?}"
        );
        assert!(m.mesh.signed_volume() > 0.0);
        assert!(largest_mirror_gap(&m.mesh, m.axis) < 0.1, "mirror partners");
        for row in &out.comparison.table {
            assert!(
                row.tape_change_mm.abs() <= 1.0,
                "{preserve:?} {}: {:+.2} mm",
                row.measure,
                row.tape_change_mm
            );
        }
        // Every torso layer keeps its section's girth (above the arm plates the mesh's rings
        // bend over the shoulders, but the layers stay horizontal).
        let lm = &m.landmarks;
        for layer in &m.torso {
            let (kept, asked) = match preserve {
                Preserve::Tape => (layer.tape_girth, layer.input_tape_girth),
                Preserve::Contour => (layer.contour_length, layer.input_contour_length),
            };
            assert!((kept - asked).abs() < 1e-6, "layer at {:.0}", layer.z);
        }

        // The torso between the crotch and the armpits lies on the input surface.
        let surface = SurfaceDistance::new(&scan.body, 10.0);
        let mut worst: f64 = 0.0;
        for layer in m.torso.iter().filter(|l| l.z > lm.crotch + 5.0 && l.z < lm.armpit() - 5.0) {
            for p in &layer.points {
                let d = surface.distance(p.extend(layer.z)).expect("the body is near");
                worst = worst.max(d);
            }
        }
        assert!(
            worst < 2.0,
            "{preserve:?}: a torso vertex is {worst:.2} mm from the input surface"
        );
    }
}

fn symmetrize_cli(args: &[&str]) -> (i32, String, String) {
    let mut all = vec!["symmetrize"];
    all.extend_from_slice(args);
    dressform(&all)
}

#[test]
fn symmetrize_writes_the_three_outputs_in_either_frame() {
    let Some(dir) = makehuman() else { return };
    let base = dir.join("base.obj");
    let out = tempfile::tempdir().unwrap();
    let (code, stdout, stderr) =
        symmetrize_cli(&[base.to_str().unwrap(), "-o", out.path().to_str().unwrap()]);
    assert_eq!(code, 0, "{stderr}");
    assert!(stdout.contains("chest") && stdout.contains("Fig. 11"), "{stdout}");
    let profiles: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.path().join("profiles.json")).unwrap()).unwrap();
    assert_eq!(profiles["format"], "dressform-profiles/1");
    let layers = profiles["layers"].as_array().unwrap();
    assert_eq!(layers.len(), 100 + 2 * 50);
    assert_eq!(layers[150]["points"].as_array().unwrap().len(), 358, "torso: rays - 2");
    let measurements: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.path().join("measurements.json")).unwrap())
            .unwrap();
    assert_eq!(measurements["table"].as_array().unwrap().len(), 3);
    assert_eq!(measurements["mirrored"].as_array().unwrap().len(), 4);

    // Canonical frame: mm, Z up, floor at 0; --scan-frame: back in decimetres, Y up.
    let canonical = dressform::body::scan::read_mesh(&out.path().join("mannequin.obj")).unwrap().0;
    let b = canonical.bounds().unwrap();
    assert!(b.min.z > 100.0 && b.max.z < 1500.0, "ankles to neck in mm: {b:?}");
    let (code, _, stderr) = symmetrize_cli(&[
        base.to_str().unwrap(),
        "-o",
        out.path().to_str().unwrap(),
        "--scan-frame",
        "--json",
    ]);
    assert_eq!(code, 0, "{stderr}");
    let scan_frame = dressform::body::scan::read_mesh(&out.path().join("mannequin.obj")).unwrap().0;
    let frame = scan::load(&base, &FrameOptions::default()).unwrap().frame;
    assert!(scan_frame.bounds().unwrap().size().y > 10.0, "decimetres, Y up");
    // Both files are rounded to 0.001 mm (in their own units): within 0.002 mm of each other.
    for (p, q) in scan_frame.positions.iter().zip(&canonical.positions) {
        assert!((frame.to_canonical(*p) - *q).length() < 2e-3, "{p} maps to {q}");
    }
}

#[test]
fn options_change_the_layer_and_ray_counts() {
    let Some(dir) = makehuman() else { return };
    let out = tempfile::tempdir().unwrap();
    let args = [
        dir.join("base.obj").to_str().unwrap().to_string(),
        "-o".into(),
        out.path().to_str().unwrap().into(),
        "--torso-layers".into(),
        "40".into(),
        "--leg-layers".into(),
        "20".into(),
        "--rays".into(),
        "120".into(),
        "--preserve".into(),
        "contour".into(),
    ];
    let (code, _, stderr) = symmetrize_cli(&args.iter().map(String::as_str).collect::<Vec<_>>());
    assert_eq!(code, 0, "{stderr}");
    let profiles: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.path().join("profiles.json")).unwrap()).unwrap();
    assert_eq!(profiles["preserve"], "contour");
    let layers = profiles["layers"].as_array().unwrap();
    assert_eq!(layers.len(), 80);
    assert_eq!(layers[0]["points"].as_array().unwrap().len(), 120);
    assert_eq!(layers[79]["points"].as_array().unwrap().len(), 118);
}

/// The legs' options through `symmetrize`: straight by default, as scanned on asking, with the
/// same hips and inseam either way; `--stop-at thigh` ends the legs at mid-thigh, closed,
/// with fewer leg layers in `profiles.json`.
#[test]
fn leg_stance_and_stop_at_thigh() {
    let Some(dir) = makehuman() else { return };
    let base = dir.join("base.obj");
    let tmp = tempfile::tempdir().unwrap();
    let build = |name: &str, flags: &[&str]| {
        let out = tmp.path().join(name);
        let mut args = vec![base.to_str().unwrap(), "-o", out.to_str().unwrap()];
        args.extend(flags);
        let (code, _, stderr) = symmetrize_cli(&args);
        assert_eq!(code, 0, "{flags:?}: {stderr}");
        let mesh = dressform::body::scan::read_mesh(&out.join("mannequin.obj")).unwrap().0;
        let profiles: serde_json::Value =
            serde_json::from_slice(&std::fs::read(out.join("profiles.json")).unwrap()).unwrap();
        (mesh, profiles)
    };
    let (straight, straight_p) = build("straight", &[]);
    let (scanned, scanned_p) = build("as-scanned", &["--legs", "as-scanned"]);
    let (thigh, thigh_p) = build("thigh", &["--stop-at", "thigh"]);

    let layers = |p: &serde_json::Value, region: &str| -> Vec<serde_json::Value> {
        let all = p["layers"].as_array().unwrap().iter();
        all.filter(|l| l["region"] == region).cloned().collect()
    };
    let centre_x = |l: &serde_json::Value| l["centre"][0].as_f64().unwrap();
    // The torso (its hip among it) bit for bit the same; every leg layer's girth too.
    assert_eq!(layers(&straight_p, "torso"), layers(&scanned_p, "torso"));
    for (a, b) in layers(&straight_p, "left_leg").iter().zip(&layers(&scanned_p, "left_leg")) {
        assert_eq!(a["z"], b["z"]);
        let (ga, gb) = (a["tape_girth"].as_f64().unwrap(), b["tape_girth"].as_f64().unwrap());
        assert!((ga - gb).abs() < 1e-6, "a leg layer's girth at {}: {ga} against {gb}", a["z"]);
    }
    // Straight: the ankle under the thigh; as scanned (MakeHuman stands 10 degrees out), out.
    let splay = |p: &serde_json::Value| {
        let left = layers(p, "left_leg");
        centre_x(&left[0]) - centre_x(&left[left.len() - 1])
    };
    assert!(splay(&straight_p).abs() < 10.0, "straight: {:.1} mm", splay(&straight_p));
    assert!(splay(&scanned_p) > 50.0, "as scanned: {:.1} mm", splay(&scanned_p));
    for (what, mesh) in [("straight", &straight), ("as scanned", &scanned), ("thigh", &thigh)] {
        let t = topology(mesh);
        assert!(t.is_closed() && t.is_manifold() && t.is_consistently_oriented(), "{what}: {t:?}");
    }
    // At the thigh: the full legs' top layers, none below mid-thigh, the torso unchanged.
    let (full, cut) = (layers(&straight_p, "left_leg"), layers(&thigh_p, "left_leg"));
    let lm = &straight_p["landmarks"];
    let (crotch, height) = (lm["crotch_mm"].as_f64().unwrap(), lm["height_mm"].as_f64().unwrap());
    let mid_thigh = 0.5 * (crotch + 0.285 * height);
    let lowest = cut[0]["z"].as_f64().unwrap();
    assert!(lowest <= mid_thigh && lowest > mid_thigh - 20.0, "{lowest} against {mid_thigh}");
    assert!(cut.len() < full.len() / 2, "{} leg layers of {}", cut.len(), full.len());
    assert_eq!(cut[..], full[full.len() - cut.len()..]);
    assert_eq!(layers(&thigh_p, "torso"), layers(&straight_p, "torso"));
    let bottom = thigh.bounds().unwrap().min.z;
    assert!((bottom - lowest).abs() < 1e-3, "the mesh ends at {bottom}, the legs at {lowest}");
}

/// A closed ellipsoid "body" of human height, without legs or arms.
fn ellipsoid(dir: &Path) -> std::path::PathBuf {
    let mut mesh = dressform::body::mesh::Mesh::default();
    let (n, m) = (48u32, 24u32);
    mesh.positions.push(DVec3::new(0.0, 0.0, 0.0));
    for j in 1..m {
        let phi = std::f64::consts::PI * j as f64 / m as f64;
        for i in 0..n {
            let t = std::f64::consts::TAU * i as f64 / n as f64;
            mesh.positions.push(DVec3::new(
                200.0 * phi.sin() * t.cos(),
                120.0 * phi.sin() * t.sin(),
                850.0 - 850.0 * phi.cos(),
            ));
        }
    }
    mesh.positions.push(DVec3::new(0.0, 0.0, 1700.0));
    let ring = |j: u32, i: u32| 1 + (j - 1) * n + i % n;
    for i in 0..n {
        mesh.triangles.push([0, ring(1, i + 1), ring(1, i)]);
        for j in 1..m - 1 {
            mesh.triangles.push([ring(j, i), ring(j, i + 1), ring(j + 1, i + 1)]);
            mesh.triangles.push([ring(j, i), ring(j + 1, i + 1), ring(j + 1, i)]);
        }
        mesh.triangles.push([ring(m - 1, i), ring(m - 1, i + 1), (m - 1) * n + 1]);
    }
    let path = dir.join("egg.ply");
    dressform::atomic_output::write_atomically(
        &path,
        &dressform::body::scan::format::Format::Ply.encode(&mesh),
    )
    .unwrap();
    path
}

#[test]
fn error_paths() {
    let tmp = tempfile::tempdir().unwrap();
    let egg = ellipsoid(tmp.path());
    let out = tmp.path().join("out");
    let egg_s = egg.to_str().unwrap();
    let out_s = out.to_str().unwrap();

    // Not a body with legs: a clear error naming the file, status 2.
    let (code, _, stderr) = symmetrize_cli(&[egg_s, "-o", out_s]);
    assert_eq!(code, 2, "{stderr}");
    assert!(stderr.contains("egg.ply") && stderr.contains("crotch"), "{stderr}");
    let (code, _, stderr) = dressform(&["measure", egg_s]);
    assert_eq!(code, 2, "{stderr}");
    // Slicing still works on any mesh, without labels.
    let (code, stdout, stderr) = dressform(&["slice", egg_s, "--heights", "850", "--json"]);
    assert_eq!(code, 0, "{stderr}");
    assert!(stderr.contains("not labelled"), "{stderr}");
    let v: serde_json::Value = serde_json::from_str(&stdout).unwrap();
    assert_eq!(v["sections"][0]["loops"][0]["label"], serde_json::Value::Null);

    let Some(dir) = makehuman() else { return };
    let base = dir.join("base.obj");
    let base_s = base.to_str().unwrap();
    for (args, expected) in [
        (vec!["--rays", "359"], "even"),
        (vec!["--rays", "4"], "at least 8"),
        (vec!["--torso-layers", "1"], "at least 2"),
        (vec!["--preserve", "area"], "invalid value"),
    ] {
        let mut all = vec![base_s, "-o", out_s];
        all.extend(args);
        let (code, _, stderr) = symmetrize_cli(&all);
        assert_eq!(code, 2, "{stderr}");
        assert!(stderr.contains(expected), "expected '{expected}': {stderr}");
    }
    // An output directory that cannot be created: status 1, naming it.
    let blocker = tmp.path().join("file");
    std::fs::write(&blocker, "x").unwrap();
    let inside = blocker.join("out");
    let (code, _, stderr) = symmetrize_cli(&[base_s, "-o", inside.to_str().unwrap()]);
    assert_eq!(code, 1, "{stderr}");
    assert!(stderr.contains("cannot create"), "{stderr}");
    let (code, _, stderr) = dressform(&["slice", base_s, "--heights", "900,abc"]);
    assert_eq!(code, 2, "{stderr}");
}

#[test]
fn measure_and_slice_json() {
    let Some(dir) = makehuman() else { return };
    let base = dir.join("base.obj");
    let (code, stdout, stderr) =
        dressform(&["measure", base.to_str().unwrap(), "--json", "--at", "1000,2000"]);
    assert_eq!(code, 0, "{stderr}");
    let v: serde_json::Value = serde_json::from_str(&stdout).unwrap();
    let crotch = v["measurements"]["crotch_height_mm"].as_f64().unwrap();
    assert!((700.0..850.0).contains(&crotch), "crotch {crotch}");
    let (chest, waist, hip) = (
        v["measurements"]["chest"]["tape_mm"].as_f64().unwrap(),
        v["measurements"]["waist"]["tape_mm"].as_f64().unwrap(),
        v["measurements"]["hip"]["tape_mm"].as_f64().unwrap(),
    );
    assert!(waist < chest && waist < hip, "{chest} {waist} {hip}");
    assert!(v["at"][0]["tape_mm"].as_f64().unwrap() > 0.0);
    assert!(v["at"][1].is_null(), "no torso above the head");

    let (code, stdout, stderr) =
        dressform(&["slice", base.to_str().unwrap(), "--heights", "500,1000,1550", "--json"]);
    assert_eq!(code, 0, "{stderr}");
    let v: serde_json::Value = serde_json::from_str(&stdout).unwrap();
    let labels = |k: usize| -> Vec<String> {
        v["sections"][k]["loops"]
            .as_array()
            .unwrap()
            .iter()
            .map(|l| l["label"].as_str().unwrap().to_string())
            .collect()
    };
    assert_eq!(labels(0).iter().filter(|l| l.ends_with("leg")).count(), 2);
    assert!(
        labels(1).contains(&"torso".to_string()) && labels(1).contains(&"left_arm".to_string())
    );
    assert!(labels(2).iter().all(|l| l == "head"));
}
