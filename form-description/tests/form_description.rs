//! Form descriptions: the shipped reference form's layout, TOML errors that name the field,
//! and validation problems that name the actuator.

use std::collections::HashSet;

use form_description::{FormDescription, FormError, REFERENCE_TOML, reference};

#[test]
fn the_reference_form_is_64_mirror_symmetric_actuators_and_8_lifts_on_9_nodes() {
    let form = reference();
    assert_eq!((form.nodes.len(), form.actuators.len(), form.lifts.len()), (9, 64, 8));
    for node in form.node_ids() {
        assert_eq!(form.actuators_of(node).len(), 8, "node {}", node.get());
    }
    // The lifts are a telescoping spine: the column carries every ring, each next lift one
    // ring fewer from the bottom, so every ring has an axis of its own.
    let carried: Vec<usize> = form.lifts.iter().map(|l| l.rings.len()).collect();
    assert_eq!(carried, [9, 7, 6, 5, 4, 3, 2, 1]);
    let (node, index) = form.locate("neck-rise").unwrap();
    assert_eq!((node.get(), index.index()), (9, 7));
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
    assert!(heights[0] > 1100.0 && heights[8] < 700.0);
    // Lifts at full stroke: a 1.95 m customer's levels (neck about 1650 mm, thighs 830).
    let raised: std::collections::BTreeMap<String, f64> =
        form.lifts.iter().map(|l| (l.id.clone(), l.stroke_mm)).collect();
    assert!(form.ring_height(&form.rings[0], &raised) > 1650.0);
    assert!(form.ring_height(&form.rings[8], &raised) > 830.0);
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
    for (name, _) in form_description::BUILTIN {
        let form = form_description::builtin(name).unwrap();
        let again = FormDescription::from_toml_str(&form.to_toml_string()).unwrap();
        assert_eq!(again, form);
    }
}

/// The male form validates (the loader would refuse it otherwise), is another layout (no
/// under-bust or abdomen ring, larger panels, 7 nodes) and its lifts give every ring an axis
/// of its own, reaching a 2.0 m customer's levels.
#[test]
fn the_male_form_is_another_valid_layout_with_its_own_spine() {
    let form = form_description::builtin("male").unwrap();
    assert_eq!((form.nodes.len(), form.actuators.len(), form.lifts.len()), (7, 48, 6));
    let rings: Vec<&str> = form.rings.iter().map(|r| r.name.as_str()).collect();
    assert_eq!(rings, ["neck", "shoulders", "chest", "waist", "hip", "thigh-l", "thigh-r"]);
    let carried: Vec<usize> = form.lifts.iter().map(|l| l.rings.len()).collect();
    assert_eq!(carried, [7, 5, 4, 3, 2, 1]);
    let chest = |f: &FormDescription| f.actuator("chest-l2").unwrap().base_radius_mm;
    assert!(chest(&form) > chest(&reference()));
    let raised: std::collections::BTreeMap<String, f64> =
        form.lifts.iter().map(|l| (l.id.clone(), l.stroke_mm)).collect();
    assert!(form.ring_height(&form.rings[0], &raised) > 1700.0);
    assert!(form_description::builtin("female").is_none());
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
        (
            "node = 1\n",
            "node = 10\n",
            "actuator `neck-front`: `node` 10 is not a `[[node]]` address",
        ),
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
    assert_eq!(
        anchors,
        [
            ("neck", "neck"),
            ("shoulders", "shoulders"),
            ("chest", "chest"),
            ("under-bust", "under-bust"),
            ("waist", "waist"),
            ("abdomen", "abdomen"),
            ("hip", "hip"),
            ("thigh-l", "thigh"),
            ("thigh-r", "thigh")
        ]
    );
    let parts: Vec<&str> = form.rings.iter().map(|r| r.part.name()).collect();
    assert_eq!(parts[..7], ["torso"; 7]);
    assert_eq!(parts[7..], ["left-leg", "right-leg"]);
    let cases: [(&str, &str, &str); 6] = [
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
        (
            "anchor = \"hip\"",
            "anchor = \"thigh\"",
            "ring `hip`: `anchor` \"thigh\" is a leg level; a torso ring has none",
        ),
        (
            "anchor = \"thigh\"",
            "anchor = \"hip\"",
            "ring `thigh-l`: `anchor` \"hip\" is a torso level; a leg ring has none",
        ),
    ];
    for (from, to, expected) in cases {
        let message = error(&edited(from, to));
        assert!(message.contains(expected), "{from} -> {to}:\n{message}\nexpected: {expected}");
    }
}

/// Lifts are checked like actuators on the bus (ids, nodes, channels, strokes) and for what
/// they carry: known rings, once each, mirror images, and rings that never meet.
#[test]
fn lifts_are_validated() {
    let cases: [(&str, &str, &str); 6] = [
        (
            "rings = [\"neck\"]",
            "rings = [\"nek\"]",
            "lift `neck-rise`: `rings` names \"nek\", not a `[[ring]]` name",
        ),
        ("rings = [\"neck\"]", "rings = []", "lift `neck-rise`: `rings` is empty"),
        (
            "rings = [\"neck\"]",
            "rings = [\"neck\", \"neck\"]",
            "lift `neck-rise`: `rings` names `neck` twice",
        ),
        (
            "rings = [\"neck\"]",
            "rings = [\"neck\", \"thigh-l\"]",
            "lift `neck-rise`: raises `thigh-l` but it does not raise its mirror `thigh-r`",
        ),
        (
            "rings = [\"neck\", \"shoulders\", \"chest\", \"under-bust\", \"waist\", \"abdomen\", \"hip\"]",
            "rings = [\"hip\"]",
            "rings `abdomen` and `hip`: the lifts can bring them to 0 mm apart",
        ),
        ("id = \"neck-rise\"", "id = \"chest-l1\"", "actuator `chest-l1`: id used twice"),
    ];
    for (from, to, expected) in cases {
        let message = error(&edited_last(from, to));
        assert!(message.contains(expected), "{from} -> {to}:\n{message}\nexpected: {expected}");
    }
    // A lift for each thigh on a node of their own, paired: valid; with another stroke or
    // unpaired: refused.
    let mut spec = reference().into_spec();
    spec.nodes.push(form_description::NodeSpec { address: 10, label: None });
    let mut left = spec.lifts[7].clone();
    (left.id, left.node, left.channel) = ("thigh-l-rise".into(), 10, 0);
    (left.rings, left.stroke_mm, left.mirror) = (vec!["thigh-l".into()], 20.0, None);
    let mut right = left.clone();
    (right.id, right.channel, right.rings) = ("thigh-r-rise".into(), 1, vec!["thigh-r".into()]);
    let with = |left: &form_description::LiftSpec, right: &form_description::LiftSpec| {
        let mut spec = spec.clone();
        spec.lifts.extend([left.clone(), right.clone()]);
        FormDescription::try_from(spec).err().unwrap_or_default()
    };
    let unpaired = with(&left, &right);
    assert_eq!(unpaired.len(), 2, "{unpaired:?}");
    assert!(
        unpaired[0]
            .to_string()
            .contains("raises `thigh-l` but it does not raise its mirror `thigh-r`")
    );
    left.mirror = Some("thigh-r-rise".into());
    assert_eq!(with(&left, &right), []);
    right.stroke_mm = 25.0;
    let unequal = with(&left, &right);
    assert_eq!(unequal.len(), 1, "{unequal:?}");
    assert!(
        unequal[0]
            .to_string()
            .contains("its mirror `thigh-r-rise` has another `stroke_mm` (20 and 25)")
    );
    // The partner raising a ring more than the mirror images: refused.
    right.stroke_mm = 20.0;
    right.rings.push("waist".into());
    let extra = with(&left, &right);
    let said = |problems: &[form_description::Problem], what: &str| {
        problems.iter().any(|p| p.to_string().contains(what))
    };
    assert!(said(&extra, "`thigh-r-rise` also raises `waist`, whose mirror"), "{extra:?}");
    // Two lifts naming one partner: refused.
    right.rings.pop();
    let mut third = left.clone();
    (third.id, third.channel) = ("thigh-l-rise-2".into(), 2);
    let mut spec3 = spec.clone();
    spec3.lifts.extend([left.clone(), right.clone(), third]);
    let conflict = FormDescription::try_from(spec3).unwrap_err();
    assert!(said(&conflict, "lift `thigh-r-rise`: paired as the mirror of both"), "{conflict:?}");
}

/// `REFERENCE_TOML` with the last occurrence of `from` replaced (the lifts come last).
fn edited_last(from: &str, to: &str) -> String {
    let at = REFERENCE_TOML.rfind(from).unwrap_or_else(|| panic!("{from}"));
    format!("{}{to}{}", &REFERENCE_TOML[..at], &REFERENCE_TOML[at + from.len()..])
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
