//! The set-point file: round trip, and errors that name the file and the field or actuator.

use std::collections::BTreeMap;

use dressform::form::setpoints::{FORMAT, SetPoints};
use dressform::input::InputError;
use form_description::reference;

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
        (
            r#"{"format": "dressform-setpoints/1", "form": "reference", "positions_mm": {"chest-l1": 999.0, "chest-l1": 12.5}}"#,
            "\"chest-l1\" is given twice",
        ),
        (
            r#"{"format": "dressform-setpoints/1", "form": "reference", "positions_mm": {}, "target_girths_mm": {"knee": 300}}"#,
            "target_girths_mm.knee: the form has no ring",
        ),
        (
            r#"{"format": "dressform-setpoints/1", "form": "reference", "positions_mm": {}, "target_girths_mm": {"waist": -1}}"#,
            "target_girths_mm.waist: -1 is not a girth in mm (above 0, at most 31415.9)",
        ),
    ];
    for (text, expected) in cases {
        let path = write(&dir, text);
        let error = SetPoints::load(&path, &form).unwrap_err().to_string();
        assert!(error.contains(expected), "{text}: {error}");
        assert!(error.contains("setpoints.json"), "{error}");
    }
    let missing = SetPoints::load(&dir.path().join("nope.json"), &form).unwrap_err();
    assert!(matches!(missing, InputError::Read { .. }), "{missing}");
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

/// A duplicated actuator id is refused by `drive` (exit 2) before anything moves.
#[test]
fn drive_refuses_a_duplicated_actuator_id() {
    let dir = tempfile::tempdir().unwrap();
    let path = write(
        &dir,
        r#"{"format": "dressform-setpoints/1", "form": "reference", "positions_mm": {"chest-l1": 999.0, "chest-l1": 12.5}}"#,
    );
    let (code, _, stderr) = crate::common::dressform(&["drive", path.to_str().unwrap(), "--sim"]);
    assert_eq!(code, 2, "{stderr}");
    assert!(stderr.contains("chest-l1") && stderr.contains("given twice"), "{stderr}");
    assert!(stderr.contains("setpoints.json"), "{stderr}");
}

/// A profiles file the reference form fits: circles of `points` points in every region.
fn profiles(points: usize) -> serde_json::Value {
    let ring = |cx: f64, r: f64| -> Vec<[f64; 2]> {
        (0..points)
            .map(|k| {
                let a = std::f64::consts::TAU * k as f64 / points as f64;
                [cx + r * a.sin(), -r * a.cos()]
            })
            .collect()
    };
    let layer = |region: &str, z: f64, cx: f64, r: f64| {
        let girth = std::f64::consts::TAU * r;
        serde_json::json!({
            "region": region, "z": z, "centre": [cx, 0.0], "points": ring(cx, r),
            "input_tape_girth": girth, "input_contour_length": girth,
            "tape_girth": girth, "contour_length": girth
        })
    };
    let mut layers = Vec::new();
    for (region, cx) in [("left_leg", 105.0), ("right_leg", -105.0)] {
        for z in [300.0, 500.0, 780.0] {
            layers.push(layer(region, z, cx, 85.0));
        }
    }
    for z in [780.0, 900.0, 1100.0, 1300.0, 1500.0] {
        layers.push(layer("torso", z, 0.0, 150.0));
    }
    serde_json::json!({
        "format": "dressform-profiles/1", "frame": "canonical", "axis_x": 0.0,
        "rays": points + 2, "preserve": "tape",
        "levels": { "chest_mm": 1250.0, "waist_mm": 1060.0, "hip_mm": 880.0 },
        "landmarks": { "height_mm": 1700.0, "crotch_mm": 780.0, "ankle_mm": 80.0,
                       "left_armpit_mm": 1290.0, "right_armpit_mm": 1290.0, "neck_mm": 1470.0,
                       "centre_x_mm": 0.0,
                       "left_armhole": { "armpit_mm": [160.0, 20.0, 1290.0],
                                         "shoulder_point_mm": [190.0, 20.0, 1400.0],
                                         "normal": [0.96, 0.0, -0.26] },
                       "right_armhole": { "armpit_mm": [-160.0, 20.0, 1290.0],
                                          "shoulder_point_mm": [-190.0, 20.0, 1400.0],
                                          "normal": [-0.96, 0.0, -0.26] } },
        "layers": layers
    })
}

/// At least ten kinds of malformed profiles: `setpoints` exits 2 naming the layer or field,
/// where a valid file of the same shape is fitted.
#[test]
fn malformed_profiles_are_refused_naming_the_field() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out.json");
    let setpoints = |value: &serde_json::Value| {
        let path = dir.path().join("profiles.json");
        std::fs::write(&path, serde_json::to_string(value).unwrap()).unwrap();
        crate::common::dressform(&[
            "setpoints",
            path.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
        ])
    };
    let (code, _, stderr) = setpoints(&profiles(64));
    assert_eq!(code, 0, "a valid file: {stderr}");
    type Break = fn(&mut serde_json::Value);
    let cases: [(&str, Break, &str); 12] = [
        (
            "every points array empty",
            |p| {
                for l in p["layers"].as_array_mut().unwrap() {
                    l["points"] = serde_json::json!([]);
                }
            },
            "layers[0].points: 0 points",
        ),
        ("no layers", |p| p["layers"] = serde_json::json!([]), "layers: empty"),
        (
            "a single torso layer",
            |p| {
                let layers = p["layers"].as_array_mut().unwrap();
                layers.truncate(7);
            },
            "layers: 1 torso layer(s)",
        ),
        (
            "no leg layers",
            |p| {
                let layers = p["layers"].as_array_mut().unwrap();
                layers.retain(|l| l["region"] == "torso");
            },
            "layers: 0 left_leg layer(s)",
        ),
        (
            "a coordinate of 1e308",
            |p| p["layers"][8]["points"][3][0] = serde_json::json!(1e308),
            "layers[8].points[3][0]: 1e308 is not within ±5000 mm",
        ),
        ("a height of 1e308", |p| p["layers"][9]["z"] = serde_json::json!(1e308), "layers[9].z"),
        (
            "heights out of order",
            |p| p["layers"][9]["z"] = serde_json::json!(850.0),
            "layers[9].z: 850 is below the torso layer before it",
        ),
        (
            "unequal point counts",
            |p| {
                p["layers"][10]["points"].as_array_mut().unwrap().truncate(40);
            },
            "layers[10].points: 40 points, the first torso layer (layers[6]) has 64",
        ),
        (
            "a level far away",
            |p| p["levels"]["waist_mm"] = serde_json::json!(-7000.0),
            "levels.waist_mm: -7000",
        ),
        (
            "a landmark far away",
            |p| p["landmarks"]["neck_mm"] = serde_json::json!(1e300),
            "landmarks.neck_mm",
        ),
        (
            "a negative girth",
            |p| p["layers"][7]["tape_girth"] = serde_json::json!(-5.0),
            "layers[7].tape_girth: -5 is not a girth",
        ),
        (
            "a centre far away",
            |p| p["layers"][2]["centre"][1] = serde_json::json!(9000.0),
            "layers[2].centre[1]: 9000",
        ),
    ];
    for (what, mut_fn, expected) in cases {
        let mut broken = profiles(64);
        mut_fn(&mut broken);
        let (code, _, stderr) = setpoints(&broken);
        assert_eq!(code, 2, "{what}: {stderr}");
        assert!(stderr.contains("profiles.json") && stderr.contains(expected), "{what}: {stderr}");
        assert!(stderr.lines().count() == 1, "{what}: one line: {stderr}");
    }
}
