//! Ground truth of a synthetic body: the measurements and landmarks it was built to have,
//! measured on the implicit surface (so they hold for the mesh up to its resolution).

use glam::DVec3;

use super::anatomy::{Anatomy, SIDE_SIGN};
use super::body::ImplicitBody;
use super::calibration::{Calibrated, SectionMeasure};
use super::warp::Segment;

/// A signed distance field (negative inside).
type Field<'a> = &'a dyn Fn(DVec3) -> f64;

/// A horizontal girth level.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GirthLevel {
    /// Height of the section.
    pub z_mm: f64,
    /// Tape girth: perimeter of the convex hull of the torso's loop (arms excluded).
    pub tape_girth_mm: f64,
    /// Length of the torso's loop itself (at least the tape girth; more where it is concave).
    pub contour_girth_mm: f64,
    /// A point inside the torso's loop (x, y): picks the torso among the section's loops.
    pub centre_xy_mm: [f64; 2],
}

/// Landmarks of one side of the body; joints are centres inside the body, the others lie on
/// the surface.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SideLandmarks {
    /// Lateral top of the shoulder (surface), x = +-shoulder width / 2.
    pub acromion: [f64; 3],
    /// Top of the gap between arm and torso (surface), in the shoulder's frontal plane.
    pub armpit: [f64; 3],
    /// Centre of the shoulder (glenohumeral) joint.
    pub shoulder_joint: [f64; 3],
    /// Centre of the elbow joint.
    pub elbow_joint: [f64; 3],
    /// Centre of the wrist joint.
    pub wrist_joint: [f64; 3],
    /// Tip of the middle finger (surface).
    pub fingertip: [f64; 3],
    /// Centre of the hip joint.
    pub hip_joint: [f64; 3],
    /// Centre of the knee joint.
    pub knee_joint: [f64; 3],
    /// Centre of the ankle joint.
    pub ankle_joint: [f64; 3],
    /// Back of the heel (surface).
    pub heel: [f64; 3],
    /// Front of the toes (surface).
    pub toe_tip: [f64; 3],
    /// Middle of the sole, on the floor.
    pub sole_centre: [f64; 3],
}

/// Landmarks of the body.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Landmarks {
    /// Top of the head (surface), at the stature.
    pub head_top: [f64; 3],
    /// Tip of the nose (surface); the nose points to -Y.
    pub nose_tip: [f64; 3],
    /// Where the neck's axis enters the torso.
    pub neck_base: [f64; 3],
    /// Lowest point of the torso between the legs (surface), at the crotch height.
    pub crotch: [f64; 3],
    /// The subject's left (+X) side.
    pub left: SideLandmarks,
    /// The subject's right (-X) side.
    pub right: SideLandmarks,
}

/// What the synthetic body is known to be.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GroundTruth {
    /// Stature: height of the top of the head above the floor.
    pub height_mm: f64,
    /// Floor to crotch.
    pub crotch_height_mm: f64,
    /// Bust point level, the largest girth below the armpits.
    pub chest: GirthLevel,
    /// Natural waist (0.62 of the stature, between the lowest rib and the iliac crest).
    pub waist: GirthLevel,
    /// Level of the buttocks' greatest protrusion.
    pub hip: GirthLevel,
    /// Horizontal distance between the acromion landmarks.
    pub shoulder_width_mm: f64,
    /// Joints and surface landmarks.
    pub landmarks: Landmarks,
}

/// The surface point where a walk from `inside` along `dir` first leaves the body.
fn exit_point(body: Field, inside: DVec3, dir: DVec3) -> DVec3 {
    let dir = dir.normalize();
    let at = |t: f64| body(inside + dir * t);
    let (mut lo, mut hi) = (0.0, 0.5);
    while at(hi) < 0.0 && hi < 3000.0 {
        lo = hi;
        hi += 0.5;
    }
    for _ in 0..50 {
        let mid = 0.5 * (lo + hi);
        if at(mid) < 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    inside + dir * (0.5 * (lo + hi))
}

/// The surface point where a walk from the outside point `outside` along `dir` first enters
/// the body, if within `reach` mm.
fn entry_point(body: Field, outside: DVec3, dir: DVec3, reach: f64) -> Option<DVec3> {
    let dir = dir.normalize();
    let at = |t: f64| body(outside + dir * t);
    let mut t = 0.0;
    while t < reach {
        let next = t + 0.5;
        if at(next) < 0.0 {
            let (mut lo, mut hi) = (t, next);
            for _ in 0..50 {
                let mid = 0.5 * (lo + hi);
                if at(mid) >= 0.0 {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            return Some(outside + dir * (0.5 * (lo + hi)));
        }
        t = next;
    }
    None
}

/// The armpit of `side`: in the shoulder's frontal plane, between the torso and the arm, the
/// highest point the gap reaches; looked for from the chest level, or from the first level
/// above it where the arm does not rest on the torso.
fn armpit(body: Field, a: &Anatomy, side: usize) -> DVec3 {
    let arm = &a.arms[side];
    let sg = SIDE_SIGN[side];
    let y = arm.shoulder.y;
    let gap_at = |z0: f64| {
        let torso_side = exit_point(body, DVec3::new(0.0, y, z0), DVec3::X * sg);
        // Where the arm begins beyond the gap (or a hand's breadth out when it is raised).
        let gap_end = entry_point(body, torso_side + DVec3::X * sg, DVec3::X * sg, 300.0)
            .unwrap_or(torso_side + DVec3::X * (sg * 100.0));
        (torso_side, gap_end)
    };
    let levels = (0..).map(|k| a.levels[2] + GAP_SEARCH_STEP_MM * f64::from(k));
    let (torso_side, gap_end) = levels
        .take_while(|&z| z < arm.shoulder.z)
        .map(gap_at)
        .find(|(t, g)| t.distance(*g) > GAP_SEARCH_STEP_MM)
        .unwrap_or_else(|| gap_at(a.levels[2]));
    let roof = |t: f64| {
        let p = torso_side.lerp(gap_end, t);
        entry_point(body, p, DVec3::Z, a.height).map_or(f64::MAX, |q| q.z)
    };
    // The roof is highest at the apex; golden-section search for it.
    let (mut lo, mut hi) = (0.02, 0.98);
    let g = 0.5 * (5f64.sqrt() - 1.0);
    for _ in 0..40 {
        let (t1, t2) = (hi - g * (hi - lo), lo + g * (hi - lo));
        let (z1, z2) = (roof(t1), roof(t2));
        // Treat "no roof" as lowest so the search stays in the gap.
        let (z1, z2) = (
            if z1 == f64::MAX { f64::MIN } else { z1 },
            if z2 == f64::MAX { f64::MIN } else { z2 },
        );
        if z1 > z2 {
            hi = t2;
        } else {
            lo = t1;
        }
    }
    let t = 0.5 * (lo + hi);
    let p = torso_side.lerp(gap_end, t);
    entry_point(body, p, DVec3::Z, a.height).unwrap_or(p)
}

/// Step (mm) of the search upward for a level where an arm resting on the torso leaves a gap.
const GAP_SEARCH_STEP_MM: f64 = 5.0;

/// The highest surface point of the part around `inside` (the head, however it is tilted):
/// the highest of the exits straight up from points on a grid around `inside`, refined.
fn highest_point(body: Field, inside: DVec3) -> DVec3 {
    let up = |x: f64, y: f64| exit_point(body, DVec3::new(x, y, inside.z), DVec3::Z);
    let mut best = up(inside.x, inside.y);
    let mut step = TOP_SEARCH_MM;
    while step > 0.05 {
        let around = (-1..=1).flat_map(|i| (-1..=1).map(move |j| (i, j)));
        let (x, y) = (best.x, best.y);
        let candidate = around
            .map(|(i, j)| up(x + f64::from(i) * step, y + f64::from(j) * step))
            .max_by(|a, b| a.z.total_cmp(&b.z))
            .unwrap_or(best);
        if candidate.z > best.z { best = candidate } else { step *= 0.5 }
    }
    best
}

/// First step (mm) of the search for the top of a tilted head: a fraction of its radius.
const TOP_SEARCH_MM: f64 = 16.0;

/// Tape and contour girth of a calibrated level as a [`GirthLevel`].
fn girth_level(body: &ImplicitBody, z: f64, m: &SectionMeasure) -> GirthLevel {
    let (x, y) = body.torso_centre(z);
    GirthLevel { z_mm: z, tape_girth_mm: m.tape, contour_girth_mm: m.contour, centre_xy_mm: [x, y] }
}

/// Measures the ground truth of the calibrated body. Landmarks of the trunk and arms are
/// found in the trunk's own frame (as designed, before the spine bends and twists) and moved
/// with it; those of the head in the head's; the legs' where they stand.
pub(crate) fn ground_truth(a: &Anatomy, cal: &Calibrated) -> GroundTruth {
    let body = &cal.body;
    let world = |q: DVec3| body.value(q);
    let in_frame = |segment: Segment| move |q: DVec3| body.value(body.warp.forward(segment, q));
    let (trunk, head) = (in_frame(Segment::Trunk), in_frame(Segment::Head));
    let on_trunk = |q: DVec3| body.warp.forward(Segment::Trunk, q).to_array();
    let sides: [SideLandmarks; 2] = std::array::from_fn(|side| {
        let arm = &a.arms[side];
        let leg = &a.legs[side];
        let above = DVec3::new(arm.acromion.x, arm.acromion.y, a.height + 10.0);
        let acromion = entry_point(&trunk, above, DVec3::NEG_Z, a.height).unwrap_or(arm.acromion);
        let [along, _, _] = arm.hand_axes;
        let fingers = arm.wrist + along * (0.7 * arm.hand_length);
        let lf = leg.foot_length;
        let heel_centre = leg.foot_point(-0.12 * lf, 0.0, 0.11 * lf);
        let toes_centre = leg.foot_point(0.62 * lf, -0.08 * leg.foot_width, 0.06 * lf);
        SideLandmarks {
            acromion: on_trunk(acromion),
            armpit: on_trunk(armpit(&trunk, a, side)),
            shoulder_joint: on_trunk(arm.shoulder),
            elbow_joint: on_trunk(arm.elbow),
            wrist_joint: on_trunk(arm.wrist),
            fingertip: on_trunk(exit_point(&trunk, fingers, along)),
            hip_joint: leg.hip.to_array(),
            knee_joint: leg.knee.to_array(),
            ankle_joint: leg.ankle.to_array(),
            heel: exit_point(&world, heel_centre, -leg.foot_forward).to_array(),
            toe_tip: exit_point(&world, toes_centre, leg.foot_forward).to_array(),
            sole_centre: leg.foot_point(0.2 * lf, 0.0, 0.0).to_array(),
        }
    });
    let hd = &a.head;
    let (cranium, _) = hd.cranium;
    let (_, _, nose_tip, _) = hd.nose;
    let on_head = |q: DVec3| body.warp.forward(Segment::Head, q);
    let head_top = highest_point(&world, on_head(cranium));
    let nose = on_head(exit_point(&head, nose_tip, DVec3::NEG_Y));
    let [hip, waist, chest] =
        std::array::from_fn(|l| girth_level(body, a.levels[l], &cal.sections[l]));
    GroundTruth {
        height_mm: head_top.z,
        crotch_height_mm: cal.crotch.1,
        chest,
        waist,
        hip,
        shoulder_width_mm: (sides[0].acromion[0] - sides[1].acromion[0]).abs(),
        landmarks: Landmarks {
            head_top: head_top.to_array(),
            nose_tip: nose.to_array(),
            neck_base: on_head(hd.neck_base).to_array(),
            crotch: [0.0, cal.crotch.0, cal.crotch.1],
            left: sides[0],
            right: sides[1],
        },
    }
}
