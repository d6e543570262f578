//! Form descriptions: the shipped reference form's layout, TOML errors that name the field,
//! and validation problems that name the actuator.

use std::collections::HashSet;

use form_description::{FormDescription, FormError, REFERENCE_TOML, reference};

#[test]
fn the_reference_form_is_64_mirror_symmetric_actuators_on_8_nodes() {
    let form = reference();
    assert_eq!((form.nodes.len(), form.actuators.len()), (8, 64));
    for node in form.node_ids() {
        assert_eq!(form.actuators_of(node).len(), 8, "node {}", node.get());
    }
    let ids: HashSet<&str> = form.actuators.iter().map(|a| a.id.as_str()).collect();
    assert_eq!(ids.len(), 64);
    let rings: Vec<&str> = form.rings.iter().map(|r| r.name.as_str()).collect();
    assert_eq!(
        rings,
        [
            "neck",
            "shoulders",
            "chest",
            "under-bust",
            "waist",
            "abdomen",
            "hip",
            "thigh-l",
            "thigh-r"
        ]
    );
    // Neck to mid-thigh, top down.
    let heights: Vec<f64> = form.rings.iter().map(|r| r.height_mm).collect();
    assert!(heights.windows(2).all(|h| h[0] >= h[1]), "{heights:?}");
    assert!(heights[0] > 1400.0 && heights[8] < 800.0);
    for a in &form.actuators {
        assert!((20.0..=60.0).contains(&a.stroke_mm), "{}: stroke {}", a.id, a.stroke_mm);
        assert!((5.0..=20.0).contains(&a.max_speed_mm_s), "{}: speed {}", a.id, a.max_speed_mm_s);
        // Its mirror partner's panel is its own mirrored across x = 0, at every extension.
        let mirror = form.mirror_of(&a.id).unwrap();
        for extension in [0.0, a.stroke_mm] {
            let [x, y, z] = form.panel_position(&a.id, extension).unwrap();
            let [mx, my, mz] = form.panel_position(&mirror.id, extension).unwrap();
            assert!((x + mx).abs() < 0.05 && (y - my).abs() < 0.05 && z == mz, "{}", a.id);
        }
    }
    // The angle convention: 0° is the front (-Y), 90° the subject's left (+X).
    let [x, y, _] = form.panel_position("chest-front", 0.0).unwrap();
    assert!(x.abs() < 1e-9 && y < -100.0);
    let [x, y, _] = form.panel_position("chest-l2", 0.0).unwrap();
    assert!(x > 100.0 && y.abs() < 1e-9);
    assert_eq!(form.mirror_of("chest-l2").unwrap().id, "chest-r2");
    assert_eq!(form.mirror_of("chest-back").unwrap().id, "chest-back");
    assert_eq!(form.mirror_of("thigh-r-outer").unwrap().id, "thigh-l-outer");
    let (node, index) = form.locate("chest-l2").unwrap();
    assert_eq!((node.get(), index.index()), (2, 2));
}

#[test]
fn a_description_round_trips_through_toml() {
    let form = reference();
    let again = FormDescription::from_toml_str(&form.to_toml_string()).unwrap();
    assert_eq!(again, form);
}

fn edited(from: &str, to: &str) -> String {
    assert!(REFERENCE_TOML.contains(from), "{from}");
    REFERENCE_TOML.replacen(from, to, 1)
}

fn error(text: &str) -> String {
    FormDescription::from_toml_str(text).unwrap_err().to_string()
}

#[test]
fn bad_toml_is_reported_with_the_field() {
    let message = error(&edited("stroke_mm = 25.0", "stroke_mm = \"long\""));
    assert!(message.contains("stroke_mm") && message.contains("line"), "{message}");
    let message = error(&edited("stroke_mm = 25.0", "strok_mm = 25.0"));
    assert!(message.contains("unknown field `strok_mm`"), "{message}");
    let message = error(&edited("channel = 0\n", ""));
    assert!(message.contains("missing field `channel`"), "{message}");
    let message = error("name = [");
    assert!(message.contains("line 1"), "{message}");
}

#[test]
fn validation_names_every_problem() {
    let cases: [(&str, &str, &str); 10] = [
        ("address = 2\n", "address = 1\n", "node 1: address used twice"),
        ("address = 8\n", "address = 64\n", "node 64: `address` must be in 1..=63"),
        (
            "channel = 1\n",
            "channel = 0\n",
            "node 1: channel 0 is used by both `neck-front` and `neck-l1`",
        ),
        (
            "stroke_mm = 25.0",
            "stroke_mm = -25.0",
            "actuator `neck-front`: `stroke_mm` = -25 must be in 0.01..=655.34",
        ),
        (
            "max_speed_mm_s = 6.0",
            "max_speed_mm_s = 0.0",
            "actuator `neck-front`: `max_speed_mm_s` = 0",
        ),
        (
            "angle_deg = 45.0",
            "angle_deg = 50.0",
            "actuators `chest-l1` and `chest-r1` are not a mirror pair: angles 50° and 315°",
        ),
        (
            "mirror = \"chest-r1\"",
            "",
            "actuator `chest-l1`: off the centre line and without a mirror partner",
        ),
        ("node = 1\n", "node = 9\n", "actuator `neck-front`: `node` 9 is not a `[[node]]` address"),
        ("ring = \"neck\"\n", "ring = \"nek\"\n", "`ring` \"nek\" is not a `[[ring]]` name"),
        ("id = \"neck-front\"", "id = \"node4\"", "actuator id \"node4\""),
    ];
    for (from, to, expected) in cases {
        let message = error(&edited(from, to));
        assert!(message.contains(expected), "{from} -> {to}:\n{message}\nexpected: {expected}");
    }
    // A right partner with a different stroke is asymmetric.
    let text = REFERENCE_TOML.replacen(
        "id = \"chest-r1\"\nnode = 2\nchannel = 7\nring = \"chest\"\nangle_deg = 315.0\nbase_radius_mm = 121.6\npanel_width_mm = 81.0\nstroke_mm = 60.0",
        "id = \"chest-r1\"\nnode = 2\nchannel = 7\nring = \"chest\"\nangle_deg = 315.0\nbase_radius_mm = 121.6\npanel_width_mm = 81.0\nstroke_mm = 50.0",
        1,
    );
    assert!(error(&text).contains("`stroke_mm` differs (60 and 50)"), "{}", error(&text));
    // Every problem at once, one per line.
    let text = edited("stroke_mm = 25.0", "stroke_mm = -1.0").replacen(
        "panel_width_mm = ",
        "panel_width_mm = -",
        1,
    );
    let message = error(&text);
    assert_eq!(message.lines().filter(|l| l.starts_with("  - ")).count(), 2, "{message}");
}

#[test]
fn a_channel_gap_and_an_off_centre_ring_without_mirror_are_refused() {
    use form_description::Problem;
    let mut form = reference().into_spec();
    form.actuators.retain(|a| a.id != "neck-l1" && a.id != "neck-r1");
    let problems = FormDescription::try_from(form).unwrap_err();
    assert_eq!(problems, [Problem::ChannelGap { address: 1, channels: vec![0, 2, 4, 5, 6, 7] }]);
    assert!(problems[0].to_string().contains("must be numbered 0..6 without gaps"));
    let message = error(&edited("mirror = \"thigh-r\"\n", ""));
    assert!(message.contains("ring `thigh-l`: is off the centre line"), "{message}");
}

#[test]
fn ring_roles_are_stated_and_checked() {
    let form = reference();
    let anchors: Vec<(&str, &str)> =
        form.rings.iter().filter_map(|r| r.anchor.map(|a| (r.name.as_str(), a.name()))).collect();
    assert_eq!(anchors, [("neck", "neck"), ("chest", "chest"), ("waist", "waist"), ("hip", "hip")]);
    let parts: Vec<&str> = form.rings.iter().map(|r| r.part.name()).collect();
    assert_eq!(parts[..7], ["torso"; 7]);
    assert_eq!(parts[7..], ["left-leg", "right-leg"]);
    let cases: [(&str, &str, &str); 4] = [
        (
            "part = \"left-leg\"\n",
            "",
            "ring `thigh-l`: `part` the ring is off the body axis (x = 105 mm)",
        ),
        ("part = \"left-leg\"", "part = \"right-leg\"", "\"right-leg\" needs its centre"),
        (
            "anchor = \"waist\"",
            "anchor = \"chest\"",
            "\"chest\" is already the anchor of ring `chest`",
        ),
        ("anchor = \"neck\"", "anchor = \"elbow\"", "unknown variant `elbow`"),
    ];
    for (from, to, expected) in cases {
        let message = error(&edited(from, to));
        assert!(message.contains(expected), "{from} -> {to}:\n{message}\nexpected: {expected}");
    }
}

#[test]
fn loading_a_file_names_it() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("form.toml");
    let missing = FormDescription::load(&path).unwrap_err();
    assert!(matches!(missing, FormError::Io { .. }));
    assert!(missing.to_string().contains("form.toml"), "{missing}");
    std::fs::write(&path, edited("address = 2\n", "address = 1\n")).unwrap();
    let invalid = FormDescription::load(&path).unwrap_err();
    assert!(invalid.to_string().starts_with(&format!("{}: invalid", path.display())), "{invalid}");
    std::fs::write(&path, REFERENCE_TOML).unwrap();
    assert_eq!(FormDescription::load(&path).unwrap(), reference());
}
