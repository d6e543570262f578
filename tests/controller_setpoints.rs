//! The set-point file: round trip, and errors that name the file and the field or actuator.

use std::collections::BTreeMap;

use dressform::setpoints::{FORMAT, SetPoints, SetPointsError};
use sim::form::reference;

fn write(dir: &tempfile::TempDir, text: &str) -> std::path::PathBuf {
    let path = dir.path().join("setpoints.json");
    std::fs::write(&path, text).unwrap();
    path
}

#[test]
fn a_file_round_trips() {
    let dir = tempfile::tempdir().unwrap();
    let positions = BTreeMap::from([("chest-l1".to_string(), 23.5), ("hip-back".to_string(), 0.0)]);
    let points = SetPoints::new("reference", positions);
    let path = dir.path().join("out.json");
    points.save(&path).unwrap();
    let text = std::fs::read_to_string(&path).unwrap();
    assert!(text.contains(FORMAT) && text.contains("\"chest-l1\": 23.5"), "{text}");
    assert_eq!(SetPoints::load(&path, &reference()).unwrap(), points);
}

#[test]
fn errors_name_the_file_and_the_problem() {
    let dir = tempfile::tempdir().unwrap();
    let form = reference();
    let cases = [
        (
            r#"{"format": "dressform-setpoints/1", "form": "reference", "positions_mm": {"chest-l9": 1}}"#,
            "positions_mm.chest-l9: the form has no actuator",
        ),
        (
            r#"{"format": "dressform-setpoints/1", "form": "other", "positions_mm": {}}"#,
            "form: the file is for \"other\"",
        ),
        (
            r#"{"format": "dressform-setpoints/2", "form": "reference", "positions_mm": {}}"#,
            "format: expected",
        ),
        (
            r#"{"format": "dressform-setpoints/1", "form": "reference", "positions_mm": {"chest-l1": "x"}}"#,
            "not a set-point file",
        ),
        (
            r#"{"format": "dressform-setpoints/1", "form": "reference", "positions_mm": {"chest-l1": 1e999}}"#,
            "not a set-point file",
        ),
        (
            r#"{"format": "dressform-setpoints/1", "form": "reference"}"#,
            "missing field `positions_mm`",
        ),
        ("[", "not a set-point file"),
    ];
    for (text, expected) in cases {
        let path = write(&dir, text);
        let error = SetPoints::load(&path, &form).unwrap_err().to_string();
        assert!(error.contains(expected), "{text}: {error}");
        assert!(error.contains("setpoints.json"), "{error}");
    }
    let missing = SetPoints::load(&dir.path().join("nope.json"), &form).unwrap_err();
    assert!(matches!(missing, SetPointsError::Read { .. }), "{missing}");
    // Non-finite values built in code are refused too.
    let nan = SetPoints::new("reference", BTreeMap::from([("chest-l1".to_string(), f64::NAN)]));
    assert!(nan.validate(&form).unwrap_err()[0].contains("not a finite number"));
}

#[test]
fn out_of_stroke_positions_are_refused_or_clamped() {
    let form = reference();
    let positions = BTreeMap::from([
        ("chest-l1".to_string(), 75.0),
        ("neck-front".to_string(), -1.0),
        ("hip-back".to_string(), 30.0),
    ]);
    let points = SetPoints::new("reference", positions);
    let refused = points.check(&form, false).unwrap_err();
    assert_eq!(
        refused.offending,
        vec![("chest-l1".to_string(), 75.0, 60.0), ("neck-front".to_string(), -1.0, 25.0)]
    );
    assert!(refused.to_string().contains("chest-l1 asks 75 mm (stroke 0..=60 mm)"), "{refused}");
    let clamped = points.check(&form, true).unwrap();
    assert_eq!(clamped.targets["chest-l1"].mm(), 60.0);
    assert_eq!(clamped.targets["neck-front"].mm(), 0.0);
    assert_eq!(clamped.targets["hip-back"].mm(), 30.0);
    assert_eq!(clamped.clamped.len(), 2);
}
