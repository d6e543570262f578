//! dressform reads its own mannequin back as a body (issue 12): the header line of
//! `mannequin.obj` (and .ply, .glb) carries its frame, landmarks and levels, so `measure`
//! reproduces the mannequin column of `measurements.json`, and `slice` and `info` work at the
//! scan's heights, from the scan's floor. STL has no header: refused with a clear message.

use crate::common;

use common::{dressform, synthetic_scan};
use serde_json::Value;
use std::path::Path;

/// Largest difference allowed between `measure` on the mannequin file and the mannequin
/// column of `measurements.json` (mm; issue 12). The file rounds coordinates to 0.001 mm.
const SAME_GIRTH_MM: f64 = 0.5;

fn json(text: &str) -> Value {
    serde_json::from_str(text).unwrap_or_else(|e| panic!("{e}: {text}"))
}

fn run_ok(args: &[&str]) -> String {
    let (code, stdout, stderr) = dressform(args);
    assert_eq!(code, 0, "dressform {args:?}: {stderr}");
    stdout
}

/// `symmetrize` of `scan` into `out` with `extra` flags: measurements.json.
fn symmetrize(scan: &Path, out: &Path, extra: &[&str]) -> Value {
    let mut args = vec!["symmetrize", scan.to_str().unwrap(), "-o", out.to_str().unwrap()];
    args.extend(extra);
    run_ok(&args);
    json(&std::fs::read_to_string(out.join("measurements.json")).unwrap())
}

fn f(v: &Value) -> f64 {
    v.as_f64().unwrap_or_else(|| panic!("not a number: {v}"))
}

#[test]
fn measure_reproduces_the_mannequin_column_in_every_format_with_a_header() {
    let tmp = tempfile::tempdir().unwrap();
    let scan = synthetic_scan(tmp.path(), 5);
    let cases: [(&str, &[&str]); 4] = [
        ("mannequin.obj", &[]),
        ("mannequin.ply", &["--format", "ply", "--units", "cm", "--up", "y"]),
        ("mannequin.glb", &["--format", "glb"]),
        ("mannequin.obj", &["--scan-frame"]),
    ];
    for (k, (name, extra)) in cases.iter().enumerate() {
        let out = tmp.path().join(format!("out{k}"));
        let written = symmetrize(&scan, &out, extra);
        let file = out.join(name);
        let measured = json(&run_ok(&["measure", file.to_str().unwrap(), "--json"]));
        for row in written["table"].as_array().unwrap() {
            let (what, ours) = (row["measure"].as_str().unwrap(), &row["mannequin"]);
            let theirs = &measured["measurements"][what];
            for key in ["z_mm", "tape_mm", "contour_mm"] {
                let (a, b) = (f(&ours[key]), f(&theirs[key]));
                println!("{name} {extra:?} {what} {key}: written {a:.3}, measured {b:.3}");
                assert!((a - b).abs() <= SAME_GIRTH_MM, "{name} {extra:?} {what} {key}");
            }
        }
        assert_eq!(measured["levels"], written["levels"], "{name} {extra:?}");
    }
}

#[test]
fn slice_and_info_work_in_the_scans_frame() {
    let tmp = tempfile::tempdir().unwrap();
    let scan = synthetic_scan(tmp.path(), 6);
    let out = tmp.path().join("out");
    let written = symmetrize(&scan, &out, &[]);
    let profiles = json(&std::fs::read_to_string(out.join("profiles.json")).unwrap());
    let lm = &profiles["landmarks"];
    let mannequin = out.join("mannequin.obj");
    let file = mannequin.to_str().unwrap();

    // Heights from the scan's floor: the mannequin stands on its ankle caps, at the ankle
    // landmark, and ends at the neck cap.
    let info = json(&run_ok(&["info", file, "--json"]));
    assert_eq!(info["frame"]["from_header"], true);
    let bottom = f(&info["body"]["bounding_box_mm"]["min"][2]);
    assert!((bottom - f(&lm["ankle_mm"])).abs() < 1.0, "bottom {bottom}, ankle {}", lm["ankle_mm"]);
    let top = f(&info["body"]["height_mm"]);
    assert!((top - f(&lm["neck_mm"])).abs() < 1.0, "top {top}, neck {}", lm["neck_mm"]);
    let text = run_ok(&["info", file]);
    assert!(text.contains("from the file's header"), "{text}");

    // The chest level: one torso loop, the mannequin's chest; the knees: one leg each side.
    let chest = &written["table"][0]["mannequin"];
    let knee = 0.6 * f(&lm["crotch_mm"]);
    let heights = format!("{},{knee}", f(&chest["z_mm"]));
    let sliced = json(&run_ok(&["slice", file, "--heights", &heights, "--json"]));
    let loops = |k: usize| sliced["sections"][k]["loops"].as_array().unwrap().clone();
    let at_chest = loops(0);
    assert_eq!(at_chest.len(), 1, "{at_chest:?}");
    assert_eq!(at_chest[0]["label"], "torso");
    let tape = f(&at_chest[0]["tape_girth_mm"]);
    assert!((tape - f(&chest["tape_mm"])).abs() <= SAME_GIRTH_MM, "{tape} vs {chest}");
    let mut at_knee: Vec<(String, f64)> = loops(1)
        .iter()
        .map(|l| (l["label"].as_str().unwrap().to_string(), f(&l["centroid_mm"][0])))
        .collect();
    at_knee.sort_by(|a, b| a.1.total_cmp(&b.1));
    let labels: Vec<&str> = at_knee.iter().map(|(l, _)| l.as_str()).collect();
    assert_eq!(labels, ["right_leg", "left_leg"], "{at_knee:?}");
}

#[test]
fn a_mannequin_is_never_smoothed() {
    // A mannequin dressform made has no scanner noise: every command takes it as it is
    // (`scan::prepare`), whatever smoothing is asked for. `slice` smoothed it before.
    let tmp = tempfile::tempdir().unwrap();
    let scan = synthetic_scan(tmp.path(), 9);
    let out = tmp.path().join("out");
    let coarse = ["--torso-layers", "20", "--leg-layers", "10", "--rays", "60"];
    let written = symmetrize(&scan, &out, &coarse);
    let mannequin = out.join("mannequin.obj");
    let chest = format!("{}", f(&written["table"][0]["mannequin"]["z_mm"]));
    let slice = |smooth: &str| {
        let file = mannequin.to_str().unwrap();
        json(&run_ok(&["slice", file, "--heights", &chest, "--smooth", smooth, "--json"]))
    };
    assert_eq!(slice("8"), slice("0"));
}

#[test]
fn an_stl_mannequin_has_no_header_and_is_refused_clearly() {
    let tmp = tempfile::tempdir().unwrap();
    let scan = synthetic_scan(tmp.path(), 7);
    let out = tmp.path().join("out");
    symmetrize(&scan, &out, &["--format", "stl"]);
    let (code, _, stderr) = dressform(&["measure", out.join("mannequin.stl").to_str().unwrap()]);
    assert_eq!(code, 2, "{stderr}");
    assert_eq!(stderr.trim().lines().count(), 1, "{stderr}");
    assert!(stderr.contains("read a mannequin from the OBJ, PLY or glb file"), "{stderr}");
    // What was seen: no arm between mid-torso and the chin, with the heights searched.
    assert!(stderr.contains("arm beside the torso from "), "{stderr}");
    assert!(stderr.contains(" mm (the chin)"), "{stderr}");
}

#[test]
fn a_damaged_header_is_a_one_line_error() {
    let tmp = tempfile::tempdir().unwrap();
    let scan = synthetic_scan(tmp.path(), 8);
    let out = tmp.path().join("out");
    symmetrize(&scan, &out, &[]);
    let text = std::fs::read_to_string(out.join("mannequin.obj")).unwrap();
    let broken = tmp.path().join("broken.obj");
    std::fs::write(&broken, text.replacen("\"rotation\":[[1.0", "\"rotation\":[[2.0", 1)).unwrap();
    let (code, _, stderr) = dressform(&["measure", broken.to_str().unwrap()]);
    assert_eq!(code, 2, "{stderr}");
    assert!(stderr.contains("header line 'dressform:': frame.rotation"), "{stderr}");
    assert_eq!(stderr.trim().lines().count(), 1, "{stderr}");
}
