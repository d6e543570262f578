//! The canonical frame on the MakeHuman body: units, up axis, height and facing are found in
//! whatever units, up axis, format and turn the body comes in.

use crate::common;

use common::{dressform, makehuman};
use dressform::atomic_output::write_atomically;
use dressform::body::mesh::Mesh;
use dressform::body::scan::format::Format;
use dressform::body::scan::{self, frame::FrameOptions};
use glam::{DMat3, DVec3};
use std::path::Path;

fn info_json(path: &Path) -> serde_json::Value {
    let (code, stdout, stderr) = dressform(&["info", "--json", path.to_str().unwrap()]);
    assert_eq!(code, 0, "{stderr}");
    serde_json::from_str(&stdout).unwrap()
}

/// The MakeHuman body in the canonical frame (mm, Z up, facing -Y).
fn canonical_body(dir: &Path) -> Mesh {
    scan::load(&dir.join("base.obj"), &FrameOptions::default()).unwrap().body
}

#[test]
fn makehuman_base_is_decimetres_y_up_1666_mm_facing_plus_z() {
    let Some(dir) = makehuman() else { return };
    let info = info_json(&dir.join("base.obj"));
    assert_eq!(info["frame"]["units"], "dm");
    assert_eq!(info["frame"]["up"], "+y");
    assert_eq!(info["frame"]["facing_axis"], "+z");
    let height = info["body"]["height_mm"].as_f64().unwrap();
    assert!((height - 1666.0).abs() <= 2.0, "height {height}");
    assert_eq!(info["body"]["closed"], true);
    assert_eq!(info["body"]["manifold"], true);
    // The helper geometry (tights, skirt, eyes, joint cubes...) is not the body.
    assert!(info["components"]["dropped"].as_array().unwrap().len() > 100);
}

#[test]
fn the_same_body_in_other_units_axes_and_formats_has_the_same_height() {
    let Some(dir) = makehuman() else { return };
    let body = canonical_body(&dir);
    let tmp = tempfile::tempdir().unwrap();
    type ToFile = fn(DVec3) -> DVec3;
    let variants: [(&str, ToFile, &str, &str); 5] = [
        ("metres_z_up.obj", |p| p / 1000.0, "m", "+z"),
        ("inches_z_up.obj", |p| p / 25.4, "in", "+z"),
        ("mm_y_up.ply", |p| DVec3::new(p.x, p.z, -p.y), "mm", "+y"),
        ("cm_z_up.stl", |p| p / 10.0, "cm", "+z"),
        ("m_minus_y_up.ply", |p| DVec3::new(p.x, -p.z, p.y) / 1000.0, "m", "-y"),
    ];
    for (name, to_file, units, up) in variants {
        let path = tmp.path().join(name);
        let format = Format::from_path(&path).unwrap();
        write_atomically(&path, &format.encode(&body.map_positions(to_file))).unwrap();
        let info = info_json(&path);
        assert_eq!(info["frame"]["units"], units, "{name}");
        assert_eq!(info["frame"]["up"], up, "{name}");
        let height = info["body"]["height_mm"].as_f64().unwrap();
        assert!((height - 1666.0).abs() <= 2.0, "{name}: height {height}");
    }
}

#[test]
fn turned_by_any_angle_about_the_vertical_it_lands_facing_minus_y() {
    let Some(dir) = makehuman() else { return };
    let body = canonical_body(&dir);
    for step in 0..48 {
        let angle = (step as f64 * 7.5 + 1.3).to_radians();
        let turn = DMat3::from_rotation_z(angle);
        let turned = body.map_positions(|p| turn * p + DVec3::new(120.0, -40.0, 0.0));
        let scan = scan::from_mesh(turned, Path::new("turned"), &FrameOptions::default()).unwrap();
        let truth = turn * DVec3::NEG_Y;
        let error = scan.frame.facing.angle_between(truth).to_degrees();
        assert!(error < 3.0, "turned {:.1} deg: facing off by {error:.2} deg", angle.to_degrees());
        // And the canonical body is where it was: same height, centred, facing -Y.
        let b = scan.body.bounds().unwrap();
        assert!((b.max.z - 1666.0).abs() <= 2.0 && b.min.z.abs() < 1e-9);
    }
}

#[test]
fn canonical_and_scan_frames_round_trip() {
    let Some(dir) = makehuman() else { return };
    let scan = scan::load(&dir.join("base.obj"), &FrameOptions::default()).unwrap();
    for p in [DVec3::new(1.0, 2.0, 3.0), DVec3::new(-4.5, 16.0, 0.2)] {
        let back = scan.frame.to_scan(scan.frame.to_canonical(p));
        assert!((back - p).length() < 1e-12);
    }
    // MakeHuman's frame: (x, y, z) dm -> (100 x, -100 z, 100 y) mm, up to a shift.
    let a = scan.frame.to_canonical(DVec3::ZERO);
    let d = scan.frame.to_canonical(DVec3::new(0.1, 0.2, 0.3)) - a;
    assert!((d - DVec3::new(10.0, -30.0, 20.0)).length() < 1e-4, "{d}");
}

#[test]
fn overrides_win_over_detection() {
    let Some(dir) = makehuman() else { return };
    let path = dir.join("base.obj");
    let (code, stdout, stderr) = dressform(&[
        "info",
        "--json",
        "--units",
        "dm",
        "--up",
        "y",
        "--facing",
        "-z",
        path.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{stderr}");
    let info: serde_json::Value = serde_json::from_str(&stdout).unwrap();
    assert_eq!(info["frame"]["units"], "dm");
    assert_eq!(info["frame"]["units_detected"], false);
    assert_eq!(info["frame"]["facing_axis"], "-z");
    assert_eq!(info["frame"]["facing_detected"], false);
    assert!((info["body"]["height_mm"].as_f64().unwrap() - 1666.0).abs() < 2.0);
}

/// The generator's default customer written as a millimetre, Z-up PLY.
fn millimetre_z_up_scan(dir: &Path) -> std::path::PathBuf {
    let body = capture_sim::generate(&capture_sim::BodyParams::default()).unwrap();
    let mesh = common::mesh_of(&body);
    let path = dir.join("customer_mm_z_up.ply");
    write_atomically(&path, &Format::Ply.encode(&mesh)).unwrap();
    path
}

#[test]
fn overrides_no_standing_person_has_are_refused_naming_the_fix() {
    let tmp = tempfile::tempdir().unwrap();
    let scan = millimetre_z_up_scan(tmp.path());
    let file = scan.to_str().unwrap();
    // (override, what the message must name)
    let cases: [(&[&str], &[&str]); 5] = [
        (&["--units", "cm"], &["17000 mm tall", "--units mm"]),
        (&["--units", "m"], &["--units mm"]),
        (&["--up", "y"], &["as tall as it is wide", "--up +z"]),
        (&["--up", "-z"], &["head is below the feet", "--up +z"]),
        (&["--up", "x"], &["--up +z"]),
    ];
    for command in ["info", "measure", "slice"] {
        for (flags, named) in cases {
            let mut args = vec![command, file];
            args.extend_from_slice(flags);
            if command == "slice" {
                args.extend(["--heights", "1000"]);
            }
            let (code, _, stderr) = dressform(&args);
            assert_eq!(code, 2, "{args:?}: {stderr}");
            assert_eq!(stderr.trim().lines().count(), 1, "one line: {stderr}");
            assert!(stderr.contains(file), "{stderr}");
            for n in named {
                assert!(stderr.contains(n), "{args:?}: {stderr:?} lacks {n:?}");
            }
        }
    }
    // The right overrides pass.
    let (code, _, stderr) = dressform(&["info", file, "--units", "mm", "--up", "z"]);
    assert_eq!(code, 0, "{stderr}");
}

/// The numbers of two JSON documents, in order, paired (the documents' shapes must match).
fn numbers_paired(a: &serde_json::Value, b: &serde_json::Value, out: &mut Vec<(f64, f64)>) {
    use serde_json::Value;
    match (a, b) {
        (Value::Number(x), Value::Number(y)) => {
            out.push((x.as_f64().unwrap(), y.as_f64().unwrap()))
        }
        (Value::Array(x), Value::Array(y)) => {
            assert_eq!(x.len(), y.len());
            x.iter().zip(y).for_each(|(x, y)| numbers_paired(x, y, out));
        }
        (Value::Object(x), Value::Object(y)) => {
            assert_eq!(x.keys().collect::<Vec<_>>(), y.keys().collect::<Vec<_>>());
            x.values().zip(y.values()).for_each(|(x, y)| numbers_paired(x, y, out));
        }
        _ => {} // names (the scan's file) differ
    }
}

#[test]
fn a_scan_in_inches_reconstructs_to_the_same_mannequin_as_in_millimetres() {
    // The demo's scan (metres), written in millimetres and in inches.
    let tmp = tempfile::tempdir().unwrap();
    let metres = common::synthetic_scan(tmp.path(), 1);
    let (body, _) = scan::read_mesh(&metres).unwrap();
    let mut runs = Vec::new();
    for (name, scale, units) in [("mm.ply", 1000.0, None), ("in.ply", 1000.0 / 25.4, None)]
        .into_iter()
        .chain([("in-given.ply", 1000.0 / 25.4, Some("in"))])
    {
        let path = tmp.path().join(name);
        std::fs::write(&path, Format::Ply.encode(&body.map_positions(|p| p * scale))).unwrap();
        let out = tmp.path().join(format!("{name}.out"));
        let mut args = vec!["reconstruct", path.to_str().unwrap(), "-o", out.to_str().unwrap()];
        if let Some(units) = units {
            args.extend(["--scan-units", units]);
        }
        let (code, _, stderr) = dressform(&args);
        assert_eq!(code, 0, "{name}: {stderr}");
        if name == "in.ply" {
            // Detected, and said so.
            assert!(stderr.contains("units: read as in"), "{stderr}");
        }
        let json = |file: &str| -> serde_json::Value {
            serde_json::from_slice(&std::fs::read(out.join(file)).unwrap()).unwrap()
        };
        runs.push((name, json("measurements.json"), json("profiles.json")));
    }
    let (_, mm_measurements, mm_profiles) = &runs[0];
    for (name, measurements, profiles) in &runs[1..] {
        let mut pairs = Vec::new();
        numbers_paired(mm_measurements, measurements, &mut pairs);
        numbers_paired(mm_profiles, profiles, &mut pairs);
        let worst = pairs.iter().map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
        assert!(pairs.len() > 100 && worst < 0.01, "{name}: differs by up to {worst} mm");
    }
}

#[test]
fn a_fit_that_fails_on_a_body_of_unusual_size_names_the_units_assumed() {
    // A customer's scan scaled to 0.7 m tall, in metres: detected as metres, a body no model
    // fits; the error says so and how to override the units.
    let tmp = tempfile::tempdir().unwrap();
    let path = tmp.path().join("small.ply");
    let (body, _) = scan::read_mesh(&common::synthetic_scan(tmp.path(), 2)).unwrap();
    std::fs::write(&path, Format::Ply.encode(&body.map_positions(|p| p * (700.0 / 1700.0))))
        .unwrap();
    let out = tmp.path().join("out");
    let (code, _, stderr) =
        dressform(&["reconstruct", path.to_str().unwrap(), "-o", out.to_str().unwrap()]);
    assert_eq!(code, 2, "{stderr}");
    let last = stderr.lines().last().unwrap();
    assert!(
        last.contains("(read as m, detected: 70")
            && last.contains(" mm tall; if wrong, pass --units): ")
            && last.contains("did not converge"),
        "{stderr}"
    );
    assert!(!out.exists());
}
