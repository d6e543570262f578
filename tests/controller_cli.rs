//! `dressform drive --sim`, `status --sim` and `estop` from the command line (real time, a
//! few seconds: homing, then short moves).

// Drives the simulated form (the `simulator` feature).
#![cfg(feature = "simulator")]

use std::process::Command;

fn dressform(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_dressform")).args(args).output().expect("dressform runs")
}

fn setpoints(dir: &tempfile::TempDir, positions: &str) -> String {
    let path = dir.path().join("setpoints.json");
    let text = format!(
        r#"{{"format": "dressform-setpoints/1", "form": "reference", "positions_mm": {{{positions}}}}}"#
    );
    std::fs::write(&path, text).unwrap();
    path.display().to_string()
}

#[test]
fn drive_on_the_simulated_form_reports_every_actuator() {
    let dir = tempfile::tempdir().unwrap();
    let file = setpoints(&dir, r#""chest-l1": 3.5, "neck-front": 2.0"#);
    let form = concat!(env!("CARGO_MANIFEST_DIR"), "/form-description/forms/reference.toml");
    let out = dressform(&["drive", &file, "--form", form, "--sim", "--json"]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{stdout}\n{}", String::from_utf8_lossy(&out.stderr));
    let report: serde_json::Value = serde_json::from_str(&stdout).unwrap();
    let actuators = report["actuators"].as_array().unwrap();
    assert_eq!(actuators.len(), 2);
    for a in actuators {
        assert_eq!(a["within_tolerance"], true, "{a}");
        assert!(a["error_mm"].as_f64().unwrap().abs() <= 0.1, "{a}");
    }
}

/// A lift is driven like any actuator, and a ring its lifts leave off its level by more than
/// `--height-tolerance` (default 5 mm) makes the drive exit 3 naming it; the male form is a
/// built-in `--form`.
#[test]
fn a_ring_off_its_level_exits_3_and_the_tolerance_is_a_flag() {
    let dir = tempfile::tempdir().unwrap();
    // The column raised 40 mm: the waist (built at 870 mm) stands at 910; its level is 922.
    let path = dir.path().join("setpoints.json");
    let text = r#"{"format": "dressform-setpoints/1", "form": "reference",
        "positions_mm": {"height": 40}, "target_heights_mm": {"waist": 922}}"#;
    std::fs::write(&path, text).unwrap();
    let file = path.display().to_string();
    let out = dressform(&["drive", &file, "--sim"]);
    let (stdout, stderr) =
        (String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr));
    assert_eq!(out.status.code(), Some(3), "{stdout}\n{stderr}");
    assert!(stderr.contains("waist 12 mm below its level (at 910 mm, 922 wanted)"), "{stderr}");
    assert!(stdout.contains("height") && stdout.contains("910.0"), "{stdout}");
    let out = dressform(&["drive", &file, "--sim", "--height-tolerance", "15"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let text =
        r#"{"format": "dressform-setpoints/1", "form": "male", "positions_mm": {"height": 10}}"#;
    std::fs::write(&path, text).unwrap();
    let out = dressform(&["drive", &file, "--sim", "--form", "male"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
}

#[test]
fn an_out_of_stroke_file_is_refused_with_its_offenders_or_clamped() {
    let dir = tempfile::tempdir().unwrap();
    let file = setpoints(&dir, r#""chest-l1": 75, "neck-front": -2, "hip-back": 1"#);
    let out = dressform(&["drive", &file, "--sim"]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(stderr.contains("chest-l1 asks 75 mm (stroke 0..=60 mm)"), "{stderr}");
    assert!(stderr.contains("neck-front asks -2 mm (stroke 0..=25 mm)"), "{stderr}");
    assert!(!stderr.contains("hip-back"), "{stderr}");

    let file = setpoints(&dir, r#""neck-front": 30"#);
    let out = dressform(&["drive", &file, "--sim", "--clamp"]);
    let (stdout, stderr) =
        (String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr));
    assert!(out.status.success(), "{stdout}\n{stderr}");
    assert!(
        stderr.contains("neck-front: 30 mm is outside the stroke, clamped to 25 mm"),
        "{stderr}"
    );
    assert!(stdout.contains("neck-front") && stdout.contains("25.00"), "{stdout}");
}

#[test]
fn status_lists_every_node_and_estop_needs_a_link() {
    let out = dressform(&["status", "--sim"]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{stdout}");
    for node in 1..=9 {
        assert!(
            stdout.contains(&format!("node {node}: Disabled (protocol 1.1, firmware 1.0.0)")),
            "{stdout}"
        );
    }
    let out = dressform(&["estop"]);
    assert_eq!(out.status.code(), Some(2));
    let out = dressform(&["estop", "--serial", "/dev/does-not-exist"]);
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("/dev/does-not-exist"));
}

#[test]
fn a_failing_log_is_named_when_it_fails_and_exits_1() {
    let dir = tempfile::tempdir().unwrap();
    let file = setpoints(&dir, r#""chest-l1": 3.5"#);
    // /dev/full takes the file's creation and refuses every write: a full disk.
    let out = dressform(&["drive", &file, "--sim", "--log", "/dev/full"]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains("candump log /dev/full"), "{stderr}");
    // Reported while the form moved, then again as the reason for the exit status.
    assert!(stderr.contains("(the move goes on)"), "{stderr}");
}

#[test]
fn the_builtin_form_serves_every_command() {
    let out = dressform(&["form", "show", "--toml"]);
    assert!(out.status.success());
    let toml = String::from_utf8_lossy(&out.stdout);
    let form = form_description::FormDescription::from_toml_str(&toml).unwrap();
    assert_eq!(form, form_description::reference());
    let out = dressform(&["form", "show"]);
    let summary = String::from_utf8_lossy(&out.stdout);
    assert!(
        summary.contains("form \"reference\": 9 nodes, 9 rings, 64 actuators, 8 lifts"),
        "{summary}"
    );
    assert!(summary.contains("waist") && summary.contains("695 .. 1038"), "{summary}");

    // estop --sim and status --sim: a simulated form that lives for the command.
    let out = dressform(&["estop", "--sim"]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{stdout}");
    assert!(stdout.contains("started for this command"), "{stdout}");
    assert_eq!(stdout.matches("EMERGENCY_STOP").count(), 9, "{stdout}");
    let out = dressform(&["status", "--sim"]);
    assert!(String::from_utf8_lossy(&out.stdout).contains("started for this command"));
    let out = dressform(&["reset", "--sim"]);
    assert!(out.status.success());
    assert!(String::from_utf8_lossy(&out.stdout).contains("no node holds a fault"));
}

#[test]
fn a_fault_during_homing_names_the_actuator_in_words() {
    let dir = tempfile::tempdir().unwrap();
    let file = setpoints(&dir, r#""chest-l1": 3.5"#);
    let out = dressform(&["drive", &file, "--sim", "--faults", "chest-l1:stall@0s"]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(
        stderr.contains("fault on node 2 (chest), actuator chest-l1: following error of"),
        "{stderr}"
    );
    for debug in ["Some(", "Faults(", "FollowingError", "{", "homing did not finish"] {
        assert!(!stderr.contains(debug), "{debug}: {stderr}");
    }
}
