//! `dressform run` end to end, as in a studio: a synthetic customer's scan file, the simulated
//! reference form served on a real pseudo-terminal (serial mapping, or slcan as behind a USB-CAN
//! adapter), and the `dressform` binary opening that device — then the simulated actuators are
//! checked against the set-points the run wrote.

use capture_sim::{Artifacts, BodyParams, capture, generate};
use dressform::body::mesh::Mesh;
use dressform::body::scan::format::Format;
use dressform::form::setpoints::SetPoints;
use form_description::reference;
use form_sim::serve::{PtyLink, ServeConfig, serve};
use glam::DVec3;

pub(crate) fn scan_file(dir: &std::path::Path) -> std::path::PathBuf {
    scan_of(dir, &BodyParams::default())
}

fn scan_of(dir: &std::path::Path, params: &BodyParams) -> std::path::PathBuf {
    let body = generate(params).unwrap();
    let raw = capture(&body, &Artifacts::typical_scanner(2));
    let mesh =
        Mesh::new(raw.positions.iter().map(|&p| DVec3::from_array(p)).collect(), raw.triangles);
    let path = dir.join("scan.ply");
    std::fs::write(&path, Format::Ply.encode(&mesh)).unwrap();
    path
}

fn run_over(transport: PtyLink, flag: &str) {
    let tmp = tempfile::tempdir().unwrap();
    let scan = scan_file(tmp.path());
    let server = serve(ServeConfig::new(reference(), transport)).unwrap();
    let out = tmp.path().join("out");
    let output = std::process::Command::new(env!("CARGO_BIN_EXE_dressform"))
        .args(["run", scan.to_str().unwrap(), flag, server.device_path().to_str().unwrap()])
        .args(["--out", out.to_str().unwrap()])
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert!(
        output.status.success(),
        "{flag}: {}\n{stdout}",
        String::from_utf8_lossy(&output.stderr)
    );
    assert!(stdout.contains("every actuator reached its set-point"), "{stdout}");

    let form = reference();
    let setpoints = SetPoints::load(&out.join("setpoints.json"), &form).unwrap();
    assert_eq!(setpoints.positions_mm.len(), form.axes().count());
    let truth = server.form().state();
    for (id, &mm) in &setpoints.positions_mm {
        let real = truth.actuator(id).unwrap().state.position_mm;
        assert!(
            (real - mm).abs() <= 0.1,
            "{flag} {id}: the simulated panel is at {real:.3} mm, set-point {mm:.3}"
        );
    }
    for name in [
        "mannequin.obj",
        "posed.obj",
        "rigged.glb",
        "fit.json",
        "profiles.json",
        "measurements.json",
    ] {
        assert!(out.join(name).is_file(), "{name}");
    }
}

#[test]
fn run_shapes_the_form_over_a_serial_pty() {
    run_over(PtyLink::SerialPty, "--serial");
}

#[test]
fn run_shapes_the_form_over_slcan() {
    run_over(PtyLink::SlcanPty, "--slcan");
}

/// A slim customer: the reference form's waist is 695 mm at its smallest; the run drives the
/// form as close as it goes and exits 3, naming the rings it could not reach and by how much.
#[test]
#[cfg(feature = "simulator")] // drives the simulated form
fn run_on_a_customer_the_form_cannot_reach_exits_3_naming_the_rings() {
    let tmp = tempfile::tempdir().unwrap();
    let slim = BodyParams {
        chest_girth_mm: 860.0,
        waist_girth_mm: 625.0,
        hip_girth_mm: 900.0,
        ..BodyParams::default()
    };
    let scan = scan_of(tmp.path(), &slim);
    let out = tmp.path().join("out");
    let output = std::process::Command::new(env!("CARGO_BIN_EXE_dressform"))
        .args(["run", scan.to_str().unwrap(), "--sim", "--out", out.to_str().unwrap()])
        .output()
        .unwrap();
    let (stdout, stderr) =
        (String::from_utf8_lossy(&output.stdout), String::from_utf8_lossy(&output.stderr));
    assert_eq!(output.status.code(), Some(3), "{stdout}\n{stderr}");
    let summary =
        stderr.lines().find(|l| l.starts_with("error: the form could not take the shape"));
    let summary = summary.unwrap_or_else(|| panic!("{stderr}"));
    // The waist: the mannequin's girth (about 625 mm) against the form's smallest (695 mm).
    let waist = summary.split(", ").find(|r| r.contains("waist not reached by"));
    let waist = waist.unwrap_or_else(|| panic!("{summary}"));
    let mm: f64 =
        waist.split("not reached by ").nth(1).unwrap().split(' ').next().unwrap().parse().unwrap();
    assert!((50.0..=90.0).contains(&mm), "{waist}");
    // Every ring in the table has a status; the waist's is the same as in the summary.
    let row = stdout.lines().rev().find(|l| l.trim_start().starts_with("waist")).unwrap();
    assert!(row.contains(&format!("not reached by {mm:.0} mm")), "{row}");
    // Notes below 1 mm are not listed.
    assert!(!stdout.contains(" 0.1 mm") && !stdout.contains(" 0.0 mm"), "{stdout}");
}
