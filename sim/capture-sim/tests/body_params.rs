//! Parameter validation: every invalid value is refused with an error naming its field, never
//! a panic. (That bodies at the corners of the allowed ranges generate, closed and with their
//! girths, is checked with dressform's slicer in the root crate's `tests/synthetic_bodies.rs`.)

use capture_sim::{BodyParams, ParamError, generate};

/// A field: its name, its setter, and a value just below and just above its range.
type Field = (&'static str, fn(&mut BodyParams, f64), f64, f64);

/// Every numeric field.
fn fields() -> Vec<Field> {
    vec![
        ("height_mm", |p, v| p.height_mm = v, 1390.0, 2110.0),
        ("chest_girth_mm", |p, v| p.chest_girth_mm = v, 640.0, 1450.0),
        ("waist_girth_mm", |p, v| p.waist_girth_mm = v, 490.0, 1110.0),
        ("hip_girth_mm", |p, v| p.hip_girth_mm = v, 760.0, 1350.0),
        ("shoulder_width_mm", |p, v| p.shoulder_width_mm = v, 300.0, 480.0),
        ("leg_length_mm", |p, v| p.leg_length_mm = v, 710.0, 860.0),
        ("bust_prominence", |p, v| p.bust_prominence = v, -0.01, 1.01),
        ("resolution_mm", |p, v| p.resolution_mm = v, 1.9, 12.1),
        ("pose.left_arm.abduction_deg", |p, v| p.pose.left_arm.abduction_deg = v, -1.0, 101.0),
        ("pose.right_arm.abduction_deg", |p, v| p.pose.right_arm.abduction_deg = v, -1.0, 101.0),
        ("pose.left_arm.flexion_deg", |p, v| p.pose.left_arm.flexion_deg = v, -31.0, 61.0),
        ("pose.right_arm.flexion_deg", |p, v| p.pose.right_arm.flexion_deg = v, -31.0, 61.0),
        (
            "pose.left_arm.elbow_flexion_deg",
            |p, v| p.pose.left_arm.elbow_flexion_deg = v,
            -1.0,
            61.0,
        ),
        (
            "pose.right_arm.elbow_flexion_deg",
            |p, v| p.pose.right_arm.elbow_flexion_deg = v,
            -1.0,
            61.0,
        ),
        (
            "pose.left_arm.shoulder_elevation_mm",
            |p, v| p.pose.left_arm.shoulder_elevation_mm = v,
            -16.0,
            41.0,
        ),
        (
            "pose.right_arm.shoulder_elevation_mm",
            |p, v| p.pose.right_arm.shoulder_elevation_mm = v,
            -16.0,
            41.0,
        ),
        ("pose.left_leg.abduction_deg", |p, v| p.pose.left_leg.abduction_deg = v, 1.9, 20.1),
        ("pose.right_leg.abduction_deg", |p, v| p.pose.right_leg.abduction_deg = v, 1.9, 20.1),
        ("pose.left_leg.toe_out_deg", |p, v| p.pose.left_leg.toe_out_deg = v, -10.1, 30.1),
        ("pose.right_leg.toe_out_deg", |p, v| p.pose.right_leg.toe_out_deg = v, -10.1, 30.1),
        ("pose.spine.lateral_bend_deg", |p, v| p.pose.spine.lateral_bend_deg = v, -12.1, 12.1),
        ("pose.spine.twist_deg", |p, v| p.pose.spine.twist_deg = v, -15.1, 15.1),
        ("pose.head_turn_deg", |p, v| p.pose.head_turn_deg = v, -70.1, 70.1),
    ]
}

/// The field an error names.
fn named_field(e: &ParamError) -> Option<&'static str> {
    match e {
        ParamError::NotFinite { field, .. }
        | ParamError::OutOfRange { field, .. }
        | ParamError::LimbTooClose { field, .. } => Some(field),
        _ => None,
    }
}

#[test]
fn every_invalid_value_names_its_field() {
    for (name, set, below, above) in fields() {
        for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY, below, above] {
            let mut p = BodyParams::default();
            set(&mut p, bad);
            let err = p.validate().expect_err(&format!("{name} = {bad} accepted"));
            assert_eq!(named_field(&err), Some(name), "{name} = {bad}: {err}");
            let message = err.to_string();
            assert!(message.contains(name), "{message}");
            // generate refuses the same parameters, without panicking.
            let refused = generate(&p).expect_err("generate accepted invalid parameters");
            assert_eq!(refused.to_string(), message);
        }
    }
}

#[test]
fn range_messages_state_the_range() {
    let p = BodyParams { leg_length_mm: 600.0, ..BodyParams::default() };
    let message = p.validate().expect_err("short legs").to_string();
    assert_eq!(
        message,
        "leg_length_mm = 600 is outside its allowed range 714 ..= 850 mm \
         (0.42 ..= 0.5 times height_mm)"
    );
    let p = BodyParams { height_mm: 2500.0, ..BodyParams::default() };
    assert_eq!(
        p.validate().expect_err("giant").to_string(),
        "height_mm = 2500 is outside its allowed range 1400 ..= 2100 mm"
    );
}

#[test]
fn arms_too_close_to_the_torso_are_refused_with_a_suggestion() {
    // Resting on the torso is a stance; a few degrees further out, a gap a scanner would blur.
    let resting = BodyParams::default().with_arm_resting_on_torso(false);
    assert_eq!(resting.validate(), Ok(()));
    assert!(
        resting.pose.right_arm.abduction_deg < BodyParams::default().pose.right_arm.abduction_deg
    );
    let mut p = resting.clone();
    p.pose.right_arm.abduction_deg += 3.0;
    let err = p.validate().expect_err("arm a few mm from the torso");
    assert_eq!(named_field(&err), Some("pose.right_arm.abduction_deg"));
    let ParamError::LimbTooClose { hint, .. } = &err else {
        panic!("{err}");
    };
    // Following the suggestion gives valid parameters.
    let suggested: f64 =
        hint.split_whitespace().find_map(|w| w.parse().ok()).expect("a suggested angle");
    p.pose.right_arm.abduction_deg = suggested;
    assert_eq!(p.validate(), Ok(()));
}
