//! `dressform demo`: the built-in customer through the whole pipeline, with outputs.

mod common;

#[test]
fn demo_runs_end_to_end_and_writes_its_outputs() {
    let out = tempfile::tempdir().unwrap();
    let dir = out.path().join("demo");
    let (code, stdout, stderr) = common::dressform(&["demo", "--out", dir.to_str().unwrap()]);
    assert_eq!(code, 0, "{stderr}");
    for name in ["scan.ply", "mannequin.obj", "profiles.json", "measurements.json"] {
        assert!(dir.join(name).is_file(), "{name} missing");
    }
    // The table: customer, scan and mannequin girths, the scan within 4 mm of the customer.
    for measure in ["chest", "waist", "hip"] {
        let line =
            stdout.lines().find(|l| l.trim_start().starts_with(measure)).expect("a table row");
        let v: Vec<f64> = line.split_whitespace().skip(1).map(|x| x.parse().unwrap()).collect();
        assert!((v[1] - v[0]).abs() < 4.0 && (v[2] - v[1]).abs() < 1.0, "{line}");
    }
    let (code, _, stderr) =
        common::dressform(&["demo", "--out", dir.to_str().unwrap(), "--seed", "4"]);
    assert_eq!(code, 0, "another customer: {stderr}");
}
