//! What the synthetic customer is: body sizes ([`BodyParams`]) and how they stand ([`Pose`]),
//! with the allowed ranges and the errors that name a field outside them ([`ParamError`]).
//! The rules that need the body's geometry (the arms' clearance, [`BodyParams::validate`],
//! [`BodyParams::random`]'s arms) are in `clearance`, which builds the anatomy from these.

use rand::rngs::ChaCha8Rng;
use rand::{RngExt, SeedableRng};

/// Sizes of the synthetic body and its pose. Lengths in millimetres.
///
/// The girths are tape girths (perimeter of the convex hull of the torso's horizontal
/// section, arms excluded) at the levels recorded in [`super::GroundTruth`]:
/// chest = bust point level (maximum girth below the armpits), waist = the narrow part between
/// the lowest rib and the iliac crest (0.62 of the height), hip = maximum protrusion of the
/// buttocks.
#[derive(Debug, Clone, PartialEq)]
pub struct BodyParams {
    /// Stature: floor to the top of the head, in the pose (1400 ..= 2100).
    pub height_mm: f64,
    /// Tape girth at the bust point level (650 ..= 1600, and 0.38 ..= 0.85 of the height).
    pub chest_girth_mm: f64,
    /// Tape girth at the natural waist (500 ..= 1600, and 0.55 ..= 1.15 of the chest girth).
    pub waist_girth_mm: f64,
    /// Tape girth at the buttocks (700 ..= 1700, and 0.80 ..= 1.40 of the chest girth).
    pub hip_girth_mm: f64,
    /// Biacromial breadth: distance between the left and right acromion points on top of the
    /// shoulders (0.18 ..= 0.28 of the height).
    pub shoulder_width_mm: f64,
    /// Crotch height, floor to crotch, in the pose (0.42 ..= 0.50 of the height).
    pub leg_length_mm: f64,
    /// Breast protrusion beyond the chest wall: 0 = flat chest, 1 = pronounced bust (0 ..= 1).
    pub bust_prominence: f64,
    /// Edge of the cubic grid the surface is meshed on (2 ..= 12 mm; default 4 mm).
    pub resolution_mm: f64,
    /// Joint angles of the standing pose.
    pub pose: Pose,
}

/// Pose of one arm. Angles in degrees.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ArmPose {
    /// Angle between the upper arm and the vertical in the frontal plane: 0 = hanging,
    /// 90 = horizontal, A-pose 35 ..= 45 (0 ..= 100). Near the body the arm must either clear
    /// the torso or rest on it (see [`BodyParams::validate`]).
    pub abduction_deg: f64,
    /// Forward swing of the arm about the shoulders' left-right axis; positive moves the hand
    /// forward (to -Y) (-30 ..= 60).
    pub flexion_deg: f64,
    /// Bend of the elbow, the forearm moving forward; 0 = straight arm (0 ..= 60).
    pub elbow_flexion_deg: f64,
    /// Shrug: how far the shoulder (acromion, shoulder joint and arm) is raised; negative
    /// lowers it (-15 ..= 40 mm).
    pub shoulder_elevation_mm: f64,
}

/// Pose of one leg. Angles in degrees.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LegPose {
    /// Angle between the leg and the vertical in the frontal plane, the foot moving outward
    /// (2 ..= 20; at 2 the legs stand together, the thighs touching below the crotch). Both
    /// feet stay flat on the floor: the leg is as long as the pose needs.
    pub abduction_deg: f64,
    /// Outward turn of the foot about the vertical (-10 ..= 30).
    pub toe_out_deg: f64,
}

/// Pose of the spine between the waist and the shoulders. Angles in degrees.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct SpinePose {
    /// Sideways bend (lateral flexion) over the spine from the waist to the shoulders;
    /// positive bends towards the subject's left (+X) (-12 ..= 12).
    pub lateral_bend_deg: f64,
    /// Twist (axial rotation) over the same band; positive turns the shoulders towards the
    /// subject's left, counter-clockwise seen from above (-15 ..= 15).
    pub twist_deg: f64,
}

/// Joint angles of the standing pose, per side. "Left" is the subject's left (+X).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pose {
    /// The subject's left arm (on the +X side).
    pub left_arm: ArmPose,
    /// The subject's right arm (on the -X side).
    pub right_arm: ArmPose,
    /// The subject's left leg.
    pub left_leg: LegPose,
    /// The subject's right leg.
    pub right_leg: LegPose,
    /// The spine's bend and twist.
    pub spine: SpinePose,
    /// Turn of the head about the neck; positive turns the face towards the subject's left
    /// (-70 ..= 70).
    pub head_turn_deg: f64,
}

impl Pose {
    /// The symmetric A-pose of body scanning: arms 40 degrees from the body, elbows slightly
    /// bent, feet a little apart and turned out.
    pub fn a_pose() -> Self {
        let arm = ArmPose {
            abduction_deg: 40.0,
            flexion_deg: 0.0,
            elbow_flexion_deg: 10.0,
            shoulder_elevation_mm: 0.0,
        };
        let leg = LegPose { abduction_deg: 6.0, toe_out_deg: 7.0 };
        Pose {
            left_arm: arm,
            right_arm: arm,
            left_leg: leg,
            right_leg: leg,
            spine: SpinePose::default(),
            head_turn_deg: 0.0,
        }
    }

    /// An asymmetric pose: the left arm raised to near horizontal and swung forward, the right
    /// shoulder lifted by 25 mm, the left leg abducted by 15 degrees.
    pub fn asymmetric_example() -> Self {
        let mut pose = Self::a_pose();
        pose.left_arm.abduction_deg = 85.0;
        pose.left_arm.flexion_deg = 15.0;
        pose.left_arm.elbow_flexion_deg = 25.0;
        pose.right_arm.shoulder_elevation_mm = 25.0;
        pose.right_arm.abduction_deg = 35.0;
        pose.left_leg.abduction_deg = 15.0;
        pose.right_leg.toe_out_deg = 15.0;
        pose
    }
}

impl Default for Pose {
    fn default() -> Self {
        Self::a_pose()
    }
}

impl Default for BodyParams {
    /// A realistic adult: 1700 mm tall, chest 960, waist 800, hip 1000, shoulders 380, crotch
    /// height 790, a moderate bust, in the A-pose, meshed at 4 mm.
    fn default() -> Self {
        BodyParams {
            height_mm: 1700.0,
            chest_girth_mm: 960.0,
            waist_girth_mm: 800.0,
            hip_girth_mm: 1000.0,
            shoulder_width_mm: 380.0,
            leg_length_mm: 790.0,
            bust_prominence: 0.5,
            resolution_mm: DEFAULT_RESOLUTION_MM,
            pose: Pose::a_pose(),
        }
    }
}

/// Default grid edge of the mesher.
pub const DEFAULT_RESOLUTION_MM: f64 = 4.0;

/// Why a parameter set cannot be turned into a body.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum ParamError {
    /// A parameter is NaN or infinite.
    #[error("{field} must be a finite number, got {value}")]
    NotFinite {
        /// The parameter, e.g. `pose.left_arm.abduction_deg`.
        field: &'static str,
        /// Its value.
        value: f64,
    },
    /// A parameter lies outside its allowed range (`rule` says how the range was derived
    /// when it depends on other parameters).
    #[error("{field} = {value} is outside its allowed range {min} ..= {max}{unit}{rule}")]
    OutOfRange {
        /// The parameter.
        field: &'static str,
        /// Its value.
        value: f64,
        /// Smallest allowed value (for these other parameters).
        min: f64,
        /// Largest allowed value.
        max: f64,
        /// Unit, with a leading space (empty for ratios).
        unit: &'static str,
        /// How the range follows from other parameters (empty when fixed).
        rule: String,
    },
    /// An arm would touch the torso (or a hand a thigh) where the sections are measured.
    #[error(
        "{field} = {value}: the {side} {part} comes within {clearance_mm:.0} mm of the {obstacle} \
         at z = {z_mm:.0} mm, at least {required_mm:.0} mm are needed; {hint}"
    )]
    LimbTooClose {
        /// The arm's abduction parameter.
        field: &'static str,
        /// Its value.
        value: f64,
        /// "left" or "right".
        side: &'static str,
        /// "upper arm", "forearm" or "hand".
        part: &'static str,
        /// "torso" or "thigh".
        obstacle: &'static str,
        /// Height where the gap is too small.
        z_mm: f64,
        /// The gap there (negative: overlap).
        clearance_mm: f64,
        /// The least gap allowed.
        required_mm: f64,
        /// What to change, e.g. "raise it to about 48 degrees".
        hint: String,
    },
    /// The body's girths or crotch height could not be matched (not expected for valid
    /// parameters; reported instead of a wrong ground truth).
    #[error("calibration failed: {0}")]
    Calibration(String),
}

/// Checks `value` is finite and within `min ..= max`.
fn check_range(
    field: &'static str,
    value: f64,
    min: f64,
    max: f64,
    unit: &'static str,
    rule: &str,
) -> Result<(), ParamError> {
    if !value.is_finite() {
        return Err(ParamError::NotFinite { field, value });
    }
    if value < min || value > max {
        return Err(ParamError::OutOfRange {
            field,
            value,
            min: round1(min),
            max: round1(max),
            unit,
            rule: rule.to_string(),
        });
    }
    Ok(())
}

/// Rounds to 0.1 for messages.
fn round1(v: f64) -> f64 {
    (v * 10.0).round() / 10.0
}

/// Checks a parameter that must lie within `[lo, hi]` times another, already valid, parameter.
fn check_ratio(
    field: &'static str,
    value: f64,
    base_name: &str,
    base: f64,
    (lo, hi): (f64, f64),
) -> Result<(), ParamError> {
    check_range(
        field,
        value,
        lo * base,
        hi * base,
        " mm",
        &format!(" ({lo} ..= {hi} times {base_name})"),
    )
}

impl BodyParams {
    /// Range checks of all fields, without the geometric clearance checks (which
    /// [`BodyParams::validate`] adds).
    pub(crate) fn validate_ranges(&self) -> Result<(), ParamError> {
        check_range("height_mm", self.height_mm, 1400.0, 2100.0, " mm", "")?;
        check_range("chest_girth_mm", self.chest_girth_mm, 650.0, 1600.0, " mm", "")?;
        check_ratio(
            "chest_girth_mm",
            self.chest_girth_mm,
            "height_mm",
            self.height_mm,
            (0.38, 0.85),
        )?;
        check_range("waist_girth_mm", self.waist_girth_mm, 500.0, 1600.0, " mm", "")?;
        check_ratio(
            "waist_girth_mm",
            self.waist_girth_mm,
            "chest_girth_mm",
            self.chest_girth_mm,
            (0.55, 1.15),
        )?;
        check_range("hip_girth_mm", self.hip_girth_mm, 700.0, 1700.0, " mm", "")?;
        check_ratio(
            "hip_girth_mm",
            self.hip_girth_mm,
            "chest_girth_mm",
            self.chest_girth_mm,
            (0.80, 1.40),
        )?;
        check_ratio(
            "shoulder_width_mm",
            self.shoulder_width_mm,
            "height_mm",
            self.height_mm,
            (0.18, 0.28),
        )?;
        check_ratio(
            "leg_length_mm",
            self.leg_length_mm,
            "height_mm",
            self.height_mm,
            (0.42, 0.50),
        )?;
        check_range("bust_prominence", self.bust_prominence, 0.0, 1.0, "", "")?;
        check_range("resolution_mm", self.resolution_mm, 2.0, 12.0, " mm", "")?;
        for (side, arm) in [("left", &self.pose.left_arm), ("right", &self.pose.right_arm)] {
            let f = |name: &'static str| arm_field(side, name);
            check_range(f("abduction_deg"), arm.abduction_deg, 0.0, 100.0, " deg", "")?;
            check_range(f("flexion_deg"), arm.flexion_deg, -30.0, 60.0, " deg", "")?;
            check_range(f("elbow_flexion_deg"), arm.elbow_flexion_deg, 0.0, 60.0, " deg", "")?;
            check_range(
                f("shoulder_elevation_mm"),
                arm.shoulder_elevation_mm,
                -15.0,
                40.0,
                " mm",
                "",
            )?;
        }
        for (side, leg) in [("left", &self.pose.left_leg), ("right", &self.pose.right_leg)] {
            let f = |name: &'static str| leg_field(side, name);
            check_range(f("abduction_deg"), leg.abduction_deg, 2.0, 20.0, " deg", "")?;
            check_range(f("toe_out_deg"), leg.toe_out_deg, -10.0, 30.0, " deg", "")?;
        }
        let spine = &self.pose.spine;
        check_range(
            "pose.spine.lateral_bend_deg",
            spine.lateral_bend_deg,
            -12.0,
            12.0,
            " deg",
            "",
        )?;
        check_range("pose.spine.twist_deg", spine.twist_deg, -15.0, 15.0, " deg", "")?;
        check_range("pose.head_turn_deg", self.pose.head_turn_deg, -70.0, 70.0, " deg", "")?;
        Ok(())
    }

    /// The sizes and pose of [`BodyParams::random`], before its arms are raised clear of the
    /// torso.
    pub(crate) fn sampled(seed: u64) -> Self {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let height = rng.random_range(1500.0..1950.0);
        let build: f64 = rng.random_range(0.0..1.0); // 0 = slim, 1 = heavy
        let femininity: f64 = rng.random_range(0.0..1.0);
        let chest = height * (0.50 + 0.19 * build + rng.random_range(-0.02..0.02));
        let waist =
            chest * (0.74 + 0.20 * build - 0.08 * femininity + rng.random_range(-0.03..0.03));
        let hip = chest * (0.98 + 0.14 * femininity - 0.05 * build + rng.random_range(-0.03..0.03));
        let shoulder = height
            * (0.215 + 0.025 * (1.0 - femininity) + 0.01 * build + rng.random_range(-0.01..0.01));
        let leg = height * rng.random_range(0.44..0.48);
        let bust = (femininity * rng.random_range(0.6..1.1)).clamp(0.0, 1.0);
        let mut arm = || ArmPose {
            abduction_deg: rng.random_range(32.0..48.0),
            flexion_deg: rng.random_range(-5.0..15.0),
            elbow_flexion_deg: rng.random_range(3.0..25.0),
            shoulder_elevation_mm: rng.random_range(-5.0..10.0),
        };
        let (left_arm, right_arm) = (arm(), arm());
        let mut leg_pose = || LegPose {
            abduction_deg: rng.random_range(4.0..10.0),
            toe_out_deg: rng.random_range(0.0..15.0),
        };
        let (left_leg, right_leg) = (leg_pose(), leg_pose());
        let mut params = BodyParams {
            height_mm: height,
            chest_girth_mm: chest.clamp(0.40 * height, 0.83 * height),
            waist_girth_mm: waist,
            hip_girth_mm: hip,
            shoulder_width_mm: shoulder,
            leg_length_mm: leg,
            bust_prominence: bust,
            resolution_mm: DEFAULT_RESOLUTION_MM,
            pose: Pose { left_arm, right_arm, left_leg, right_leg, ..Pose::a_pose() },
        };
        params.waist_girth_mm =
            params.waist_girth_mm.clamp(0.57 * params.chest_girth_mm, 1.12 * params.chest_girth_mm);
        params.hip_girth_mm =
            params.hip_girth_mm.clamp(0.82 * params.chest_girth_mm, 1.38 * params.chest_girth_mm);
        params
    }
}

/// Name of a field of an arm pose, e.g. `pose.left_arm.abduction_deg`.
pub(crate) fn arm_field(side: &str, name: &'static str) -> &'static str {
    match (side, name) {
        ("left", "abduction_deg") => "pose.left_arm.abduction_deg",
        ("left", "flexion_deg") => "pose.left_arm.flexion_deg",
        ("left", "elbow_flexion_deg") => "pose.left_arm.elbow_flexion_deg",
        ("left", _) => "pose.left_arm.shoulder_elevation_mm",
        (_, "abduction_deg") => "pose.right_arm.abduction_deg",
        (_, "flexion_deg") => "pose.right_arm.flexion_deg",
        (_, "elbow_flexion_deg") => "pose.right_arm.elbow_flexion_deg",
        _ => "pose.right_arm.shoulder_elevation_mm",
    }
}

/// Name of a field of a leg pose, e.g. `pose.right_leg.toe_out_deg`.
fn leg_field(side: &str, name: &'static str) -> &'static str {
    match (side, name) {
        ("left", "abduction_deg") => "pose.left_leg.abduction_deg",
        ("left", _) => "pose.left_leg.toe_out_deg",
        (_, "abduction_deg") => "pose.right_leg.abduction_deg",
        _ => "pose.right_leg.toe_out_deg",
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn default_and_random_bodies_are_valid() {
        assert_eq!(BodyParams::default().validate(), Ok(()));
        for seed in 0..200 {
            let p = BodyParams::random(seed);
            assert_eq!(p.validate(), Ok(()), "seed {seed}: {p:?}");
        }
        let asym = BodyParams { pose: Pose::asymmetric_example(), ..BodyParams::default() };
        assert_eq!(asym.validate(), Ok(()));
    }

    #[test]
    fn random_is_reproducible_and_varied() {
        assert_eq!(BodyParams::random(7), BodyParams::random(7));
        let heights: Vec<f64> = (0..50).map(|s| BodyParams::random(s).height_mm).collect();
        let (lo, hi) =
            heights.iter().fold((f64::MAX, f64::MIN), |(lo, hi), &h| (lo.min(h), hi.max(h)));
        assert!(lo < 1600.0 && hi > 1850.0, "heights {lo}..{hi}");
        let chests: Vec<f64> = (0..50).map(|s| BodyParams::random(s).chest_girth_mm).collect();
        let (lo, hi) =
            chests.iter().fold((f64::MAX, f64::MIN), |(lo, hi), &c| (lo.min(c), hi.max(c)));
        assert!(lo < 900.0 && hi > 1150.0, "chests {lo}..{hi}");
    }
}
