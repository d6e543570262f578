//! Clearance rules: where the girths are measured, an arm either stays apart from the torso
//! (so a scan shows a clear gap) or rests on it (a scan shows them touching); a gap of a few
//! millimetres, which a scanner blurs, is refused, and so is an arm sunk into the torso. The
//! hands stay apart from the thighs. Checked on the designed anatomy, before calibration
//! (the girths a tape measures leave the arms out either way: see `ImplicitBody::value_without_arms`).

use glam::DVec3;

use super::anatomy::{Anatomy, SIDE_NAME};
use super::params::{BodyParams, ParamError, arm_field};
use super::torso::Loft;
use super::warp::Segment;

/// Least gap (mm) between an arm and the torso at the girth levels, and between a hand and a
/// thigh: more than the widest blend below the shoulder (the upper arm's, 18 mm), so the arms
/// leave the torso's sections untouched, and far more than the 9 mm below which a blend would
/// bridge the gap.
pub(crate) const LIMB_CLEARANCE_MM: f64 = 20.0;

/// Horizontal clearance between a limb segment and the torso at height `z`, if the segment
/// crosses it: distance from the segment's axis to the torso boundary (enlarged 2% for the
/// calibration and by the bust on the front) minus the segment's horizontal half-thickness.
fn torso_clearance(a: &Anatomy, z: f64, from: DVec3, to: DVec3, radius: f64) -> Option<f64> {
    if (from.z - z) * (to.z - z) > 0.0 || (from.z - to.z).abs() < 1e-9 {
        return None;
    }
    let t = (from.z - z) / (from.z - to.z);
    let axis = from.lerp(to, t);
    let cos_tilt = (from.z - to.z).abs() / from.distance(to);
    let r_eff = radius / cos_tilt.max(0.25);
    let section = Loft::new(&a.knots).at(z);
    let (dx, dy) = (axis.x, axis.y - section.centre_y());
    let r = dx.hypot(dy);
    if r < 1e-9 {
        return Some(-r_eff);
    }
    let mut reach = 1.02 * section.boundary_radius(dx / r, dy / r);
    if dy < 0.0 {
        reach += a.bust_protrusion * (-dy / r);
    }
    Some(r - reach - r_eff)
}

/// How deep (mm) an arm resting on the torso may press into it: soft tissue gives a little.
pub(crate) const MAX_PRESS_MM: f64 = 8.0;
/// How deep an arm put to rest on the torso presses into it (mm).
const REST_PRESS_MM: f64 = 2.0;

/// Distance between the point `p` and the segment `a`-`b`.
fn point_segment_distance(p: DVec3, a: DVec3, b: DVec3) -> f64 {
    let ab = b - a;
    let t = ((p - a).dot(ab) / ab.length_squared().max(1e-12)).clamp(0.0, 1.0);
    p.distance(a + ab * t)
}

/// A limb closer to the torso or a thigh than [`LIMB_CLEARANCE_MM`].
struct Violation {
    side: usize,
    part: &'static str,
    obstacle: &'static str,
    z: f64,
    gap: f64,
}

/// The first clearance violation of the arms on `sides`: an arm segment crossing a girth level
/// too close to the torso, or a hand too close to a thigh.
fn first_violation(a: &Anatomy, sides: &[usize], resting_allowed: bool) -> Option<Violation> {
    for &side in sides {
        let arm = &a.arms[side];
        if let Some(closest) = closest_to_torso(a, side)
            && !(resting_allowed && (-MAX_PRESS_MM..=0.0).contains(&closest.gap))
            && closest.gap < LIMB_CLEARANCE_MM
        {
            return Some(closest);
        }
        let hand_points = [
            (arm.wrist, arm.r_wrist),
            (arm.wrist.lerp(arm.fingertip, 0.5), 0.24 * arm.hand_length),
            (arm.fingertip, 0.1 * arm.hand_length),
        ];
        for leg in &a.legs {
            for (point, radius) in hand_points {
                // The hand moves with the spine, the thigh does not.
                let point = a.warp.forward(Segment::Trunk, point);
                let gap = point_segment_distance(point, leg.hip, leg.knee) - leg.r_hip - radius;
                if gap < LIMB_CLEARANCE_MM {
                    return Some(Violation {
                        side,
                        part: "hand",
                        obstacle: "thigh",
                        z: point.z,
                        gap,
                    });
                }
            }
        }
    }
    None
}

/// Where the arm on `side` comes closest to the torso at the girth levels (its gap negative
/// where it overlaps), if it crosses any.
fn closest_to_torso(a: &Anatomy, side: usize) -> Option<Violation> {
    let arm = &a.arms[side];
    let segments = [
        ("upper arm", arm.shoulder, arm.elbow, arm.r_upper),
        ("forearm", arm.elbow, arm.wrist, arm.r_forearm),
        ("hand", arm.wrist, arm.fingertip, 0.24 * arm.hand_length),
    ];
    a.levels
        .iter()
        .flat_map(|&z| segments.iter().map(move |s| (z, s)))
        .filter_map(|(z, &(part, from, to, radius))| {
            let gap = torso_clearance(a, z, from, to, radius)?;
            Some(Violation { side, part, obstacle: "torso", z, gap })
        })
        .min_by(|x, y| x.gap.total_cmp(&y.gap))
}

/// Lowers the arm on `side` until it rests on the torso (pressing [`REST_PRESS_MM`] into
/// it at the girth level where it comes closest); unchanged if no abduction does.
fn rest_arm_on_torso(p: &mut BodyParams, side: usize) {
    let resting = (0..=400).rev().map(|k| f64::from(k) * 0.25).find(|&deg| {
        let mut q = p.clone();
        *abduction_mut(&mut q, side) = deg;
        closest_to_torso(&Anatomy::new(&q), side).is_some_and(|c| c.gap <= -REST_PRESS_MM)
    });
    if let Some(deg) = resting {
        *abduction_mut(p, side) = deg;
    }
}

/// The abduction of the arm on `side`.
fn abduction_mut(p: &mut BodyParams, side: usize) -> &mut f64 {
    if side == 0 { &mut p.pose.left_arm.abduction_deg } else { &mut p.pose.right_arm.abduction_deg }
}

/// The least abduction (whole degrees, at most 100) at which the arm on `side` clears the
/// torso (not resting on it) and its hand the thighs.
fn least_clear_abduction(p: &BodyParams, side: usize) -> Option<f64> {
    let mut q = p.clone();
    let mut deg = abduction_mut(&mut q, side).ceil();
    while deg <= 100.0 {
        *abduction_mut(&mut q, side) = deg;
        if first_violation(&Anatomy::new(&q), &[side], false).is_none() {
            return Some(deg);
        }
        deg += 1.0;
    }
    None
}

/// Checks that each arm clears the torso by [`LIMB_CLEARANCE_MM`] at the chest, waist and hip
/// levels or rests on it (pressing at most [`MAX_PRESS_MM`] into it), and that each hand
/// clears both thighs; the error names the arm's abduction and suggests a value that clears.
fn check_clearances(a: &Anatomy, p: &BodyParams) -> Result<(), ParamError> {
    let Some(v) = first_violation(a, &[0, 1], true) else {
        return Ok(());
    };
    let mut q = p.clone();
    let hint = match least_clear_abduction(p, v.side) {
        Some(deg) => format!("raise it to about {deg:.0} degrees"),
        None => "no abduction up to 100 degrees clears it: reduce the arm's flexion or the \
                 torso's girths"
            .to_string(),
    };
    Err(ParamError::LimbTooClose {
        field: arm_field(SIDE_NAME[v.side], "abduction_deg"),
        value: *abduction_mut(&mut q, v.side),
        side: SIDE_NAME[v.side],
        part: v.part,
        obstacle: v.obstacle,
        z_mm: v.z,
        clearance_mm: v.gap,
        required_mm: LIMB_CLEARANCE_MM,
        hint,
    })
}

impl BodyParams {
    /// Checks every field against its allowed range (see the field docs), then that the arms
    /// stay clear of the torso at the chest, waist and hip levels and the hands clear of the
    /// thighs. The error names the first offending field.
    pub fn validate(&self) -> Result<(), ParamError> {
        self.validate_ranges()?;
        check_clearances(&Anatomy::new(self), self)
    }

    /// A random but plausible adult, reproducible from `seed`: stature 1500 ..= 1950 mm, builds
    /// from slim to heavy, male- to female-typical proportions, and a varied A-pose (arms
    /// 32 ..= 48 degrees, raised further when a heavy torso needs it). Always passes
    /// [`BodyParams::validate`].
    pub fn random(seed: u64) -> Self {
        Self::sampled(seed).with_arms_clear()
    }

    /// These parameters with each arm raised, if needed, until it clears the torso at the
    /// girth levels by the clearance rule's margin and its hand clears the thighs.
    pub fn with_arms_clear(mut self) -> Self {
        open_arms_until_clear(&mut self);
        self
    }

    /// These parameters with the arm on the subject's left (`left`) or right side lowered
    /// until it rests on the torso, as an arm hanging at the side does: it touches the torso
    /// at the girth level where it comes closest. Passes [`BodyParams::validate`] when the
    /// hand then clears the thighs.
    pub fn with_arm_resting_on_torso(mut self, left: bool) -> Self {
        rest_arm_on_torso(&mut self, if left { 0 } else { 1 });
        self
    }
}

/// Raises each arm's abduction to the least value at which it clears the torso and the hand
/// the thighs (if one up to 100 degrees does); used by [`BodyParams::random`].
fn open_arms_until_clear(p: &mut BodyParams) {
    for side in 0..2 {
        if let Some(deg) = least_clear_abduction(p, side) {
            *abduction_mut(p, side) = deg.max(*abduction_mut(p, side));
        }
    }
}
