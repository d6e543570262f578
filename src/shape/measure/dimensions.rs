//! A tailor's measurement set, named as in ISO 8559-1, taken on a [`SegmentedBody`] at its
//! measurement [`Levels`]: values in, values out, no stage re-deriving the regions. Each rule is stated on its field and in docs/measurements.md ("The measurement set"), so that a tailor can
//! check it with a tape; lengths in millimetres, angles in degrees, heights above the floor.

use super::arms::{ArmMeasures, arms};
use super::neck_and_shoulders::{midline_profile, neck_and_shoulders};
use super::{Girth, Levels, deepest_fold, forward, heights_between as heights};
use crate::body::regions::Region;
use crate::body::segmented_body::SegmentedBody;
use crate::body::slice::Contour;
use glam::{DVec2, DVec3};
use serde::Serialize;

/// A measurement taken on both sides of the body.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Bilateral {
    /// On the subject's left (+X).
    pub left: f64,
    /// On the subject's right.
    pub right: f64,
    /// Left minus right.
    pub difference: f64,
}

impl Bilateral {
    pub(super) fn new(left: f64, right: f64) -> Bilateral {
        Bilateral { left, right, difference: left - right }
    }
}

/// The body dimensions of ISO 8559-1 that a scan shows (see each field for its rule).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct BodyDimensions {
    /// Stature: floor to the top of the head.
    pub stature_mm: f64,
    /// Neck girth: the tape girth of the neck at its narrowest level between the shoulders
    /// and the head (horizontal).
    pub neck_girth_mm: f64,
    /// Neck-base girth: around the base of the neck through the front neck point (jugular
    /// notch), both side neck points and the back neck point (cervicale), in their plane
    /// ([`crate::shape::measure::NeckAndShoulders`]).
    pub neck_base_girth_mm: f64,
    /// Shoulder width (biacromial breadth): the horizontal distance between the two shoulder
    /// points (acromions), found as the armholes' shoulder points.
    pub shoulder_width_mm: f64,
    /// Across shoulder: from one shoulder point to the other over the back of the neck base,
    /// along the surface in the plane through both shoulder points and the back neck point.
    pub across_shoulder_mm: f64,
    /// Across back: horizontally across the back from armhole to armhole, half way up the
    /// armholes, between the arm plates ([`crate::shape::measure::NeckAndShoulders`]); NaN (null in
    /// JSON) where a plate does not cut the torso there.
    pub across_back_mm: f64,
    /// Across front: as across back, over the front.
    pub across_front_mm: f64,
    /// Shoulder slope: the angle below horizontal of the line from the side of the neck (the
    /// neck section's outermost point at the neck level) to the shoulder point.
    pub shoulder_slope_deg: Bilateral,
    /// Chest girth: the fullest horizontal tape girth under the armpits and across the bust
    /// points ([`super::chest_girth`]).
    pub chest_girth_mm: f64,
    /// Chest height: floor to the chest girth's level.
    pub chest_height_mm: f64,
    /// Bust girth: the horizontal tape girth across the bust points, below the lower armpit
    /// (the chest level of [`Levels`]: the most forward level above the fold under the bust,
    /// or the nipple line of the standard proportions on a flat chest).
    pub bust_girth_mm: f64,
    /// Underbust girth: the horizontal tape girth where the front is set farthest back
    /// between the chest level and 10% of the stature below it (the fold under the breasts).
    pub underbust_girth_mm: f64,
    /// Waist girth: the horizontal tape girth at the waist level.
    pub waist_girth_mm: f64,
    /// Waist height: floor to the waist level.
    pub waist_height_mm: f64,
    /// High hip girth: the horizontal tape girth midway between the waist and hip levels.
    pub high_hip_girth_mm: f64,
    /// Hip girth: the horizontal tape girth at the hip level (the buttocks' greatest
    /// protrusion).
    pub hip_girth_mm: f64,
    /// Hip height: floor to the hip level.
    pub hip_height_mm: f64,
    /// Thigh girth: horizontal tape girth of each leg just below the buttocks, at
    /// [`THIGH_BELOW_CROTCH`] of the stature below the crotch.
    pub thigh_girth_mm: Bilateral,
    /// Knee girth: horizontal tape girth of each leg at the knee, taken at
    /// [`KNEE_OF_CROTCH`] of the crotch height.
    pub knee_girth_mm: Bilateral,
    /// Calf girth: the largest horizontal tape girth of each leg between the knee and the
    /// ankle.
    pub calf_girth_mm: Bilateral,
    /// Ankle girth: the smallest horizontal tape girth of each leg above the foot (at the
    /// ankle landmark, the legs' narrowest level between 3% and 15% of the stature).
    pub ankle_girth_mm: Bilateral,
    /// Upper-arm girth: perpendicular to the arm's axis, midway between the armpit and the
    /// elbow ([`crate::shape::measure::ArmMeasures::upper_arm`]); NaN (null in JSON) for an arm raised too high to
    /// be followed down its horizontal loops.
    pub upper_arm_girth_mm: Bilateral,
    /// Wrist girth: the narrowest girth perpendicular to the arm's axis above the hand
    /// ([`crate::shape::measure::ArmMeasures::wrist`]); NaN as the upper arm's.
    pub wrist_girth_mm: Bilateral,
    /// Arm length: shoulder point to the elbow, then down the arm to the wrist
    /// ([`crate::shape::measure::ArmMeasures::length`]); NaN as the upper arm's.
    pub arm_length_mm: Bilateral,
    /// Inside leg length: floor to the crotch (where the legs part).
    pub inside_leg_mm: f64,
    /// Back waist length: from the back of the neck at the neck level down the back's
    /// midline, over its curve, to the waist level.
    pub back_waist_length_mm: f64,
    /// Front waist length: from the front of the neck at the neck level down the front's
    /// midline, over the chest, to the waist level.
    pub front_waist_length_mm: f64,
}

/// How far below the crotch the thigh girth is taken, as a fraction of the stature: 2%,
/// about 3.5 cm on an adult, just under the gluteal fold where the thigh is round.
pub const THIGH_BELOW_CROTCH: f64 = 0.02;
/// The knee's height as a fraction of the crotch height: the knee joint lies at 0.285 of the
/// stature and the crotch at 0.47 (Drillis and Contini's segment proportions): 0.6.
pub const KNEE_OF_CROTCH: f64 = 0.6;
/// How far below the chest the underbust is looked for, as a fraction of the stature.
const UNDERBUST_SPAN: f64 = 0.10;
/// The least depth of a fold under the bust (mm): the typical scanner's noise (sigma 1 mm,
/// the generator's `capture::Artifacts::typical_scanner`) leaves no dent this deep after smoothing; the
/// MakeHuman base body's fold is 3 mm deep.
const MIN_FOLD_MM: f64 = 1.0;

fn tape(c: &Option<Contour>) -> f64 {
    c.as_ref().map_or(0.0, Contour::tape_girth)
}

/// The length of the torso's midline profile from `from` up to `to` (front or back).
fn midline_length(body: &SegmentedBody, from: f64, to: f64, front: bool) -> f64 {
    let profile = midline_profile(body, from, to, front);
    profile.windows(2).map(|w| w[0].distance(w[1])).sum()
}

/// One measurement of both arms, NaN (null in JSON) for an arm not measured.
fn bilateral(arms: &[Option<ArmMeasures>; 2], pick: impl Fn(&ArmMeasures) -> f64) -> Bilateral {
    let side = |a: &Option<ArmMeasures>| a.as_ref().map_or(f64::NAN, &pick);
    Bilateral::new(side(&arms[0]), side(&arms[1]))
}

/// The tape girth of the left and right leg at each of `zs`: per height (left, right).
fn leg_girths(body: &SegmentedBody, zs: &[f64]) -> Vec<(f64, f64)> {
    let left = body.sections_of(Region::LeftLeg, zs);
    let right = body.sections_of(Region::RightLeg, zs);
    left.iter().zip(&right).map(|(l, r)| (tape(l), tape(r))).collect()
}

/// The underbust girth and its level: the fold under the bust ([`underbust_in`]) among the
/// torso's levels between the chest level and [`UNDERBUST_SPAN`] of the stature below it.
/// `None` if the torso has no loops there.
pub fn underbust(body: &SegmentedBody, levels: &Levels) -> Option<Girth> {
    let profile = underbust_profile(body, levels);
    let k = underbust_in(&profile)?;
    Some(Girth::of(profile[k].0, &profile[k].1))
}

/// The level of the fold under the bust ([`underbust_fold`]), if the body has one.
pub fn underbust_fold_level(body: &SegmentedBody, levels: &Levels) -> Option<f64> {
    let profile = underbust_profile(body, levels);
    underbust_fold(&profile).map(|k| profile[k].0)
}

/// The torso's sections in [`underbust_band`], by ascending height.
fn underbust_profile(body: &SegmentedBody, levels: &Levels) -> Vec<(f64, Contour)> {
    let under = heights(underbust_band(levels, body.landmarks().height).0, levels.chest);
    (under.iter().copied())
        .zip(body.torso_sections(&under))
        .filter_map(|(z, c)| Some((z, c?)))
        .collect()
}

/// The heights (low, high) between which the underbust is looked for on a body of stature
/// `height`: from [`UNDERBUST_SPAN`] of it below the chest level up to the chest level.
pub fn underbust_band(levels: &Levels, height: f64) -> (f64, f64) {
    (levels.chest - UNDERBUST_SPAN * height, levels.chest)
}

/// Which of `profile`'s sections (by ascending height, within [`underbust_band`]) is the
/// underbust: the fold under the bust, the level set farthest back behind the front-most
/// levels both above it (the bust) and below it (ribs or belly). Merely the level set
/// farthest back would be the chest level itself where that lies above the bust, at the
/// armpits (the MakeHuman base body: underbust = chest). A front without a fold keeps the
/// level set farthest back. `None` for an empty profile.
pub fn underbust_in(profile: &[(f64, Contour)]) -> Option<usize> {
    let fronts: Vec<f64> = profile.iter().map(|(_, c)| forward(c)).collect();
    let set_back = || (0..profile.len()).min_by(|&a, &b| fronts[a].total_cmp(&fronts[b]));
    underbust_fold(profile).or_else(set_back)
}

/// The fold under the bust in `profile` (as [`underbust_in`]), if it has one at least
/// `MIN_FOLD_MM` deep.
pub fn underbust_fold(profile: &[(f64, Contour)]) -> Option<usize> {
    let fronts: Vec<f64> = profile.iter().map(|(_, c)| forward(c)).collect();
    deepest_fold(&fronts, MIN_FOLD_MM).map(|(k, _)| k)
}

/// The body dimensions of `body` with its measurement `levels`.
pub fn dimensions(body: &SegmentedBody, levels: &Levels) -> BodyDimensions {
    let m = body.landmarks();
    let h = m.height;
    let torso = |zs: &[f64]| body.torso_sections(zs);

    let underbust = underbust(body, levels).map_or(0.0, |g| g.tape);
    let chest = super::chest_girth(body, levels);

    let main =
        torso(&[levels.chest, levels.waist, 0.5 * (levels.waist + levels.hip), levels.hip, m.neck]);
    // Shoulder slope from the side of the neck at the neck level to each shoulder point.
    let neck_loop = main[4].clone().unwrap_or_default();
    let neck_side = |sign: f64| {
        neck_loop
            .points
            .iter()
            .copied()
            .max_by(|a, b| (sign * a.x).total_cmp(&(sign * b.x)))
            .unwrap_or(DVec2::new(m.centre_x, 0.0))
            .extend(m.neck)
    };
    let slope = |point: DVec3, side: DVec3| {
        let run = (point.truncate() - side.truncate()).length().max(f64::EPSILON);
        ((side.z - point.z) / run).atan().to_degrees()
    };
    let (ls, rs) = (m.left_armhole.shoulder_point, m.right_armhole.shoulder_point);

    // Legs: thigh, knee, ankle at their levels; the calf the largest between knee and ankle.
    let knee_z = KNEE_OF_CROTCH * m.crotch;
    let fixed = leg_girths(body, &[m.crotch - THIGH_BELOW_CROTCH * h, knee_z, m.ankle]);
    let calf = leg_girths(body, &heights(m.ankle, knee_z));
    let largest = |pick: fn(&(f64, f64)) -> f64| calf.iter().map(pick).fold(0.0, f64::max);
    let pair = |(l, r): (f64, f64)| Bilateral::new(l, r);
    let arms = arms(body);
    let upper = neck_and_shoulders(body);
    let upper_value =
        |pick: fn(&super::NeckAndShoulders) -> f64| upper.as_ref().map_or(f64::NAN, pick);

    BodyDimensions {
        stature_mm: h,
        neck_girth_mm: neck_loop.tape_girth(),
        neck_base_girth_mm: upper_value(|u| u.neck_base.length),
        shoulder_width_mm: (ls.x - rs.x).abs(),
        across_shoulder_mm: upper_value(|u| u.across_shoulder.length),
        across_back_mm: upper_value(|u| u.across_back),
        across_front_mm: upper_value(|u| u.across_front),
        shoulder_slope_deg: Bilateral::new(slope(ls, neck_side(1.0)), slope(rs, neck_side(-1.0))),
        chest_girth_mm: chest.map_or(0.0, |g| g.tape),
        chest_height_mm: chest.map_or(f64::NAN, |g| g.z),
        bust_girth_mm: tape(&main[0]),
        underbust_girth_mm: underbust,
        waist_girth_mm: tape(&main[1]),
        waist_height_mm: levels.waist,
        high_hip_girth_mm: tape(&main[2]),
        hip_girth_mm: tape(&main[3]),
        hip_height_mm: levels.hip,
        thigh_girth_mm: pair(fixed[0]),
        knee_girth_mm: pair(fixed[1]),
        calf_girth_mm: Bilateral::new(largest(|g| g.0), largest(|g| g.1)),
        ankle_girth_mm: pair(fixed[2]),
        upper_arm_girth_mm: bilateral(&arms, |a| a.upper_arm.girth),
        wrist_girth_mm: bilateral(&arms, |a| a.wrist.girth),
        arm_length_mm: bilateral(&arms, |a| a.length),
        inside_leg_mm: m.crotch,
        back_waist_length_mm: midline_length(body, levels.waist, m.neck, false),
        front_waist_length_mm: midline_length(body, levels.waist, m.neck, true),
    }
}
