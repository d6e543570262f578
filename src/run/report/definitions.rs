//! What each measurement of the report means: its name and the ISO 8559-1 definition in one
//! line, as a tailor would take it with a tape, for every body dimension
//! [`crate::shape::measure::BodyDimensions`] reports, in its order. How dressform finds each
//! one on a scan is in docs/measurements.md ("The measurement set"); where its rule stands in
//! for a landmark a scan does not show, the line says so after "here". ISO 8559-1:2017's
//! clause numbers are not given: they were not checked against the standard's text.

/// One measurement of the report.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Definition {
    /// Its name in `measure --json` and in the `unreliable` list (`wrist_girth_mm`).
    pub key: &'static str,
    /// Its name for a person.
    pub name: &'static str,
    /// Its ISO 8559-1 definition, in one line.
    pub definition: &'static str,
}

/// Every body dimension, in [`crate::shape::measure::BodyDimensions`]'s order.
pub const DEFINITIONS: [Definition; 27] = [
    Definition {
        key: "stature_mm",
        name: "Stature",
        definition: "Vertical distance from the floor to the top of the head, standing erect.",
    },
    Definition {
        key: "neck_girth_mm",
        name: "Neck girth",
        definition: "Girth of the neck at its narrowest, just below the larynx.",
    },
    Definition {
        key: "neck_base_girth_mm",
        name: "Neck-base girth",
        definition: "Girth around the base of the neck through the front, side and back neck \
                     points.",
    },
    Definition {
        key: "shoulder_width_mm",
        name: "Shoulder width",
        definition: "Horizontal distance between the two shoulder points (acromions).",
    },
    Definition {
        key: "across_shoulder_mm",
        name: "Across shoulder",
        definition: "From one shoulder point to the other over the back of the neck base, along \
                     the body.",
    },
    Definition {
        key: "across_back_mm",
        name: "Across back",
        definition: "Across the back from armhole to armhole, halfway up the armholes (here \
                     between the arm plates).",
    },
    Definition {
        key: "across_front_mm",
        name: "Across front",
        definition: "Across the front from armhole to armhole, halfway up the armholes (here \
                     between the arm plates).",
    },
    Definition {
        key: "shoulder_slope_deg",
        name: "Shoulder slope",
        definition: "Angle below the horizontal of the line from the side of the neck to the \
                     shoulder point.",
    },
    Definition {
        key: "chest_girth_mm",
        name: "Chest girth",
        definition: "Maximum horizontal girth under the armpits, over the shoulder blades and \
                     across the chest.",
    },
    Definition {
        key: "chest_height_mm",
        name: "Chest height",
        definition: "Vertical distance from the floor to the chest girth's level.",
    },
    Definition {
        key: "bust_girth_mm",
        name: "Bust girth",
        definition: "Horizontal girth across the bust points (here the nipple line's \
                     proportion on a flat chest).",
    },
    Definition {
        key: "underbust_girth_mm",
        name: "Underbust girth",
        definition: "Horizontal girth of the chest just below the breasts.",
    },
    Definition {
        key: "waist_girth_mm",
        name: "Waist girth",
        definition: "Horizontal girth at the natural waist, between the lowest rib and the hip \
                     bone (here the narrowest level).",
    },
    Definition {
        key: "waist_height_mm",
        name: "Waist height",
        definition: "Vertical distance from the floor to the waist.",
    },
    Definition {
        key: "high_hip_girth_mm",
        name: "High hip girth",
        definition: "Horizontal girth midway between the waist and the hip.",
    },
    Definition {
        key: "hip_girth_mm",
        name: "Hip girth",
        definition: "Horizontal girth around the buttocks at their greatest protrusion.",
    },
    Definition {
        key: "hip_height_mm",
        name: "Hip height",
        definition: "Vertical distance from the floor to the hip girth's level.",
    },
    Definition {
        key: "thigh_girth_mm",
        name: "Thigh girth",
        definition: "Horizontal girth of the thigh at its top, just below the gluteal fold.",
    },
    Definition {
        key: "knee_girth_mm",
        name: "Knee girth",
        definition: "Horizontal girth around the knee.",
    },
    Definition {
        key: "calf_girth_mm",
        name: "Calf girth",
        definition: "Horizontal girth of the calf at its largest.",
    },
    Definition {
        key: "ankle_girth_mm",
        name: "Ankle girth",
        definition: "Girth of the leg at its narrowest, just above the ankle bones.",
    },
    Definition {
        key: "upper_arm_girth_mm",
        name: "Upper-arm girth",
        definition: "Girth of the upper arm, square to it, midway between the armpit and the \
                     elbow.",
    },
    Definition {
        key: "wrist_girth_mm",
        name: "Wrist girth",
        definition: "Girth of the wrist at its narrowest, square to the arm, above the hand.",
    },
    Definition {
        key: "arm_length_mm",
        name: "Arm length",
        definition: "From the shoulder point over the elbow to the wrist, the arm hanging.",
    },
    Definition {
        key: "inside_leg_mm",
        name: "Inside leg",
        definition: "Vertical distance from the floor to the crotch.",
    },
    Definition {
        key: "back_waist_length_mm",
        name: "Back waist length",
        definition: "From the back of the neck down the spine's curve to the waist.",
    },
    Definition {
        key: "front_waist_length_mm",
        name: "Front waist length",
        definition: "From the front of the neck down the middle of the front, over the chest, \
                     to the waist.",
    },
];

/// The unit of a measurement named `key`, from its suffix (`_mm`, `_deg`), as the report
/// prints it.
pub fn unit(key: &str) -> &'static str {
    if key.ends_with("_deg") { "°" } else { "mm" }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_measurement_has_one_definition_of_one_line() {
        for (k, d) in DEFINITIONS.iter().enumerate() {
            assert!(d.key.ends_with("_mm") || d.key.ends_with("_deg"), "{}", d.key);
            assert!(DEFINITIONS[..k].iter().all(|e| e.key != d.key), "{} twice", d.key);
            assert!(d.definition.ends_with('.') && !d.definition.contains('\n'), "{}", d.key);
            assert!(d.definition.len() <= 120, "{}: more than a line", d.key);
        }
        assert_eq!((unit("shoulder_slope_deg"), unit("stature_mm")), ("°", "mm"));
    }
}
