//! Anatomy: where the joints and landmarks of a body are and how thick each segment is,
//! derived from [`BodyParams`] with anthropometric proportions (fractions of the stature and
//! of the girths), posed by the joint angles.
//!
//! Frame: millimetres, Z up, floor at z = 0, +X = the subject's left, the subject faces -Y;
//! x = 0 is the mid-sagittal plane and y = 0 the mid-depth of the waist section.

use glam::{DQuat, DVec3};

use super::params::BodyParams;
use super::torso::Section;
use super::warp::SpineWarp;

/// Reference stature the proportions below were drawn for.
const REF_HEIGHT: f64 = 1700.0;

/// Side signs: index 0 is the left side (+X), 1 the right side (-X).
pub(crate) const SIDE_SIGN: [f64; 2] = [1.0, -1.0];

/// Side names, by index.
pub(crate) const SIDE_NAME: [&str; 2] = ["left", "right"];

/// One arm: shoulder girdle, the three segments and the hand's frame.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Arm {
    /// Acromion as designed (the lateral top of the shoulder, x = +-shoulder width / 2).
    pub acromion: DVec3,
    /// Trapezius: round cone from beside the neck (radius `.2`) to under the acromion (radius
    /// `.3`); just inside the shoulder's surface when the shoulder is level, it carries the
    /// shoulder line up when the shoulder is lifted.
    pub trapezius: (DVec3, DVec3, f64, f64),
    /// Deltoid ellipsoid centre and semi-axes (x, y, z).
    pub deltoid: (DVec3, DVec3),
    /// Shoulder joint centre.
    pub shoulder: DVec3,
    /// Elbow joint centre.
    pub elbow: DVec3,
    /// Wrist joint centre.
    pub wrist: DVec3,
    /// Tip of the hand (on the hand's axis).
    pub fingertip: DVec3,
    /// Radius of the upper arm at the shoulder.
    pub r_upper: f64,
    /// Radius at the elbow.
    pub r_elbow: f64,
    /// Radius of the forearm's bulge.
    pub r_forearm: f64,
    /// Radius at the wrist.
    pub r_wrist: f64,
    /// Hand frame: along the fingers, across the palm (towards the thumb), and out of the back
    /// of the hand (the palm faces the other way, towards the body in the A-pose).
    pub hand_axes: [DVec3; 3],
    /// Hand length (wrist to fingertip).
    pub hand_length: f64,
}

/// One leg: joints, radii and the foot's frame.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Leg {
    /// Hip joint centre.
    pub hip: DVec3,
    /// Knee joint centre (on the line from hip to ankle).
    pub knee: DVec3,
    /// Ankle joint centre.
    pub ankle: DVec3,
    /// Radius of the thigh at the hip joint.
    pub r_hip: f64,
    /// Radius at mid-thigh.
    pub r_thigh_mid: f64,
    /// Radius at the knee.
    pub r_knee: f64,
    /// Radius of the calf at its widest.
    pub r_calf: f64,
    /// Radius at the ankle.
    pub r_ankle: f64,
    /// Horizontal unit vector towards the toes.
    pub foot_forward: DVec3,
    /// Horizontal unit vector to the foot's outer side.
    pub foot_lateral: DVec3,
    /// Heel to toe.
    pub foot_length: f64,
    /// Width at the ball.
    pub foot_width: f64,
}

impl Leg {
    /// Point of the foot frame: `u` mm forward of the ankle, `v` mm lateral, at height `z`.
    pub fn foot_point(&self, u: f64, v: f64, z: f64) -> DVec3 {
        let p = self.ankle + self.foot_forward * u + self.foot_lateral * v;
        p.with_z(z)
    }
}

/// Neck and head.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Head {
    /// Bottom of the neck's axis (inside the torso).
    pub neck_base: DVec3,
    /// Top of the neck's axis (under the skull).
    pub neck_top: DVec3,
    /// Neck radius.
    pub r_neck: f64,
    /// Cranium ellipsoid: centre and semi-axes.
    pub cranium: (DVec3, DVec3),
    /// Face and jaw ellipsoid: centre and semi-axes.
    pub jaw: (DVec3, DVec3),
    /// Nose: round cone from the bridge to the tip, with their radii.
    pub nose: (DVec3, f64, DVec3, f64),
    /// Ears: centre (left side; the right one is mirrored) and semi-axes.
    pub ear: (DVec3, DVec3),
}

/// The whole body's design before calibration.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Anatomy {
    /// Stature.
    pub height: f64,
    /// Requested crotch height.
    pub crotch_height: f64,
    /// Requested tape girths at the hip, waist and chest levels.
    pub girths: [f64; 3],
    /// Heights of the hip, waist and chest levels.
    pub levels: [f64; 3],
    /// Torso knots, bottom to top, sized so each level's section has its girth.
    pub knots: Vec<Section>,
    /// Top plane of the torso (inside the neck).
    pub torso_top: f64,
    /// Height of the armpit knot: the chest's calibration scale holds up to it.
    pub armpit_knot: f64,
    /// Height above which the torso keeps its designed size (calibration scale 1).
    pub scale_free_above: f64,
    /// Breast ellipsoid (left; the right one is mirrored): centre and semi-axes.
    pub breast: (DVec3, DVec3),
    /// Buttock ellipsoid (left; the right one is mirrored): centre and semi-axes.
    pub buttock: (DVec3, DVec3),
    /// How far the breasts stand out of the chest wall.
    pub bust_protrusion: f64,
    /// Left and right arm.
    pub arms: [Arm; 2],
    /// Left and right leg.
    pub legs: [Leg; 2],
    /// Neck and head.
    pub head: Head,
    /// The spine's bend and twist and the head's turn.
    pub warp: SpineWarp,
}

/// Reference torso knot: its shape for the 1700 mm reference body, and how much of its size
/// follows the hip, waist and chest girths.
struct RefKnot {
    half_width: f64,
    y_front: f64,
    y_back: f64,
    n_front: f64,
    n_back: f64,
    follows: [f64; 3],
}

/// A reference knot: half-width, front and back y, front and back exponents, and the weights
/// of the hip, waist and chest girths in its size.
const fn knot(w: f64, yf: f64, yb: f64, nf: f64, nb: f64, follows: [f64; 3]) -> RefKnot {
    RefKnot { half_width: w, y_front: yf, y_back: yb, n_front: nf, n_back: nb, follows }
}

/// Torso knots bottom to top. The shoulder-joint and acromion widths are replaced by the
/// shoulder width's, the neck base is sized from the neck.
const REF_KNOTS: [RefKnot; 11] = [
    knot(140.0, -55.0, 78.0, 2.2, 2.2, [1.0, 0.0, 0.0]), // crotch
    knot(165.0, -70.0, 100.0, 2.2, 2.3, [1.0, 0.0, 0.0]), // gluteal fold
    knot(178.0, -82.0, 118.0, 2.3, 2.3, [1.0, 0.0, 0.0]), // hip
    knot(160.0, -98.0, 94.0, 2.2, 2.3, [0.5, 0.5, 0.0]), // abdomen
    knot(140.0, -100.0, 78.0, 2.1, 2.4, [0.0, 1.0, 0.0]), // waist
    knot(146.0, -104.0, 94.0, 2.2, 2.6, [0.0, 0.3, 0.7]), // under-bust
    knot(156.0, -110.0, 106.0, 2.2, 2.8, [0.0, 0.0, 1.0]), // chest
    knot(150.0, -100.0, 110.0, 2.3, 2.8, [0.0, 0.0, 1.0]), // armpit
    knot(0.0, -88.0, 104.0, 2.4, 2.8, [0.0, 0.0, 1.0]),  // shoulder joints
    knot(0.0, -70.0, 96.0, 2.3, 2.5, [0.0, 0.0, 1.0]),   // acromion
    knot(0.0, 0.0, 0.0, 2.0, 2.0, [0.0, 0.0, 1.0]),      // neck base
];

/// The knots of [`REF_KNOTS`] by name: their indices, bottom to top.
const CROTCH_KNOT: usize = 0;
const GLUTEAL_FOLD_KNOT: usize = 1;
const HIP_KNOT: usize = 2;
const ABDOMEN_KNOT: usize = 3;
const WAIST_KNOT: usize = 4;
const UNDERBUST_KNOT: usize = 5;
const CHEST_KNOT: usize = 6;
const ARMPIT_KNOT: usize = 7;
const SHOULDER_JOINT_KNOT: usize = 8;
const ACROMION_KNOT: usize = 9;
const NECK_BASE_KNOT: usize = 10;

/// Index of the hip, waist and chest knots in [`REF_KNOTS`].
const LEVEL_KNOTS: [usize; 3] = [HIP_KNOT, WAIST_KNOT, CHEST_KNOT];

// Numbers below without a cited source are the generator's own design, chosen so that its
// customers' sections look like scanned bodies' (tests/synthetic_bodies.rs in the root crate
// checks the bodies they make).

/// Fractions of the stature: the shoulder-joint knot (where the torso's horizontal scale is
/// back to 1), the acromion knot, the neck-base knot, and the torso's top plane.
const Z_SHOULDER_KNOT: f64 = 0.80;
const Z_ACROMION: f64 = 0.82;
const Z_NECK_KNOT: f64 = 0.842;
const Z_TORSO_TOP: f64 = 0.85;
/// The armpit knot, a fraction of the stature: between the nipple line (0.720) and the
/// shoulder joint (0.80).
const Z_ARMPIT_KNOT: f64 = 0.765;
/// The waist level, a fraction of the stature: the natural waist lies at the elbow's level with
/// the arms hanging (0.630 H, Drillis and Contini); the generator's customers have it a
/// centimetre and a half lower.
const WAIST_OF_STATURE: f64 = 0.62;
/// The chest level, a fraction of the stature: the nipple line (0.720 H, Drillis and Contini).
const CHEST_OF_STATURE: f64 = 0.72;
/// The hip level, a fraction of the way from the crotch up to the waist: low on the pelvis,
/// where the buttocks protrude most.
const HIP_FROM_CROTCH: f64 = 0.3;
/// How far below the crotch the torso's lowest knot lies, a fraction of the stature: the
/// torso reaches down between the thighs' tops.
const CROTCH_KNOT_BELOW: f64 = 0.01;
/// The gluteal fold knot, a fraction of the way from the crotch up to the hip level.
const GLUTEAL_FOLD_FROM_CROTCH: f64 = 0.35;
/// The under-bust knot, a fraction of the way from the waist up to the chest.
const UNDERBUST_FROM_WAIST: f64 = 0.6;

/// A belly starts to round where the waist is this fraction of the hip girth, and is fully
/// round [`BELLY_SPAN`] further.
const BELLY_FROM_RATIO: f64 = 0.8;
const BELLY_SPAN: f64 = 0.25;
/// A full belly brings the abdomen's and waist's fronts this fraction forward, and narrows
/// them by [`BELLY_NARROWING`].
const BELLY_FORWARD: f64 = 0.4;
const BELLY_NARROWING: f64 = 0.06;
/// Hips as large as the chest are neutral; the hip-to-chest ratio this far off either way
/// widens (or narrows) the knots up to the hip by [`HIP_WIDENING`].
const HIPNESS_SPAN: f64 = 0.25;
const HIP_WIDENING: f64 = 0.06;

/// How far inside half the shoulder width the shoulder-joint and acromion knots end, as
/// fractions of the stature (the deltoids fill out the rest).
const SHOULDER_JOINT_INSET: f64 = 0.005;
const ACROMION_INSET: f64 = 0.012;
/// The neck-base knot in neck radii: half-width, and how far its front and back lie from the
/// neck's axis (the neck is deeper behind: the trapezius).
const NECK_BASE_HALF_WIDTH: f64 = 1.25;
const NECK_BASE_FRONT: f64 = 1.05;
const NECK_BASE_BACK: f64 = 1.2;

/// How far the breasts stand out of the chest wall on a body of [`REF_CHEST_MM`] (mm): this
/// much at bust prominence 0, plus [`BUST_PER_PROMINENCE_MM`] times the prominence; in
/// proportion to the chest girth on others.
const BUST_BASE_MM: f64 = 6.0;
const BUST_PER_PROMINENCE_MM: f64 = 50.0;
/// The reference body's chest girth (mm): [`BodyParams::default`]'s.
const REF_CHEST_MM: f64 = 960.0;
/// The breast ellipsoid in the chest knot's half-widths: its centre's distance from the
/// midline and its semi-axes across and (at least) deep; its height is [`BREAST_RZ_OF_RX`] of
/// its width, and it is at least [`BREAST_MIN_DEPTH_MM`] deeper than it protrudes.
const BREAST_X: f64 = 0.5;
const BREAST_RX: f64 = 0.42;
const BREAST_RY: f64 = 0.3;
const BREAST_RZ_OF_RX: f64 = 0.9;
const BREAST_MIN_DEPTH_MM: f64 = 10.0;
/// The buttock ellipsoid: its centre's distance from the midline and its width in the hip
/// knot's half-widths, its depth in the hip knot's depths, how far behind the hip knot's back
/// it reaches (in depths), and how far above the hip level it reaches (a fraction of the
/// stature).
const BUTTOCK_X: f64 = 0.5;
const BUTTOCK_RX: f64 = 0.45;
const BUTTOCK_RY: f64 = 0.3;
const BUTTOCK_BEHIND: f64 = 0.06;
const BUTTOCK_ABOVE_HIP: f64 = 0.02;

impl Anatomy {
    /// Designs the body for `p` (which must pass the range checks of
    /// [`BodyParams::validate`]).
    pub fn new(p: &BodyParams) -> Anatomy {
        let h = p.height_mm;
        let crotch = p.leg_length_mm;
        let girths = [p.hip_girth_mm, p.waist_girth_mm, p.chest_girth_mm];
        let levels = level_heights(p);
        let [z_hip, z_waist, z_chest] = levels;
        let knot_z = knot_heights(p, levels);

        let mut knots = sized_knots(&shaped_knots(p, knot_z), girths);
        let chest = knots[CHEST_KNOT];
        let head = design_head(p, &chest);
        shape_shoulders(&mut knots, p, &head);
        let (breast, bust_protrusion) = design_breast(p, &chest, z_chest);
        let buttock = design_buttock(p, &knots[HIP_KNOT], z_hip);
        let arms = [0, 1].map(|side| design_arm(p, side, &chest, &head));
        let legs = [0, 1].map(|side| design_leg(p, side, &knots[HIP_KNOT]));

        Anatomy {
            height: h,
            crotch_height: crotch,
            girths,
            levels,
            knots,
            torso_top: Z_TORSO_TOP * h,
            armpit_knot: knot_z[ARMPIT_KNOT],
            scale_free_above: Z_SHOULDER_KNOT * h,
            breast,
            buttock,
            bust_protrusion,
            arms,
            legs,
            warp: spine_warp(p, z_waist, &head),
            head,
        }
    }
}

/// The heights of the hip, waist and chest levels.
fn level_heights(p: &BodyParams) -> [f64; 3] {
    let (h, crotch) = (p.height_mm, p.leg_length_mm);
    let z_waist = WAIST_OF_STATURE * h;
    let z_chest = CHEST_OF_STATURE * h;
    let z_hip = crotch + HIP_FROM_CROTCH * (z_waist - crotch);
    [z_hip, z_waist, z_chest]
}

/// The heights of the torso knots, bottom to top, from the `levels` (hip, waist, chest).
fn knot_heights(p: &BodyParams, [z_hip, z_waist, z_chest]: [f64; 3]) -> [f64; 11] {
    let (h, crotch) = (p.height_mm, p.leg_length_mm);
    let mut z = [0.0; 11];
    z[CROTCH_KNOT] = crotch - CROTCH_KNOT_BELOW * h;
    z[GLUTEAL_FOLD_KNOT] = crotch + GLUTEAL_FOLD_FROM_CROTCH * (z_hip - crotch);
    z[HIP_KNOT] = z_hip;
    z[ABDOMEN_KNOT] = 0.5 * (z_hip + z_waist);
    z[WAIST_KNOT] = z_waist;
    z[UNDERBUST_KNOT] = z_waist + UNDERBUST_FROM_WAIST * (z_chest - z_waist);
    z[CHEST_KNOT] = z_chest;
    z[ARMPIT_KNOT] = Z_ARMPIT_KNOT * h;
    z[SHOULDER_JOINT_KNOT] = Z_SHOULDER_KNOT * h;
    z[ACROMION_KNOT] = Z_ACROMION * h;
    z[NECK_BASE_KNOT] = Z_NECK_KNOT * h;
    z
}

/// The reference knots at `knot_z`, shaped for `p`: a round belly when the waist nears the
/// hips, wider hips when they exceed the chest.
fn shaped_knots(p: &BodyParams, knot_z: [f64; 11]) -> Vec<Section> {
    let belly =
        ((p.waist_girth_mm / p.hip_girth_mm - BELLY_FROM_RATIO) / BELLY_SPAN).clamp(0.0, 1.0);
    let hipness = ((p.hip_girth_mm / p.chest_girth_mm - 1.0) / HIPNESS_SPAN).clamp(-1.0, 1.0);
    REF_KNOTS
        .iter()
        .zip(knot_z)
        .enumerate()
        .map(|(i, (r, z))| {
            let mut s = Section {
                z,
                half_width: r.half_width,
                y_front: r.y_front,
                y_back: r.y_back,
                n_front: r.n_front,
                n_back: r.n_back,
            };
            if i == ABDOMEN_KNOT || i == WAIST_KNOT {
                s.y_front *= 1.0 + BELLY_FORWARD * belly;
                s.half_width *= 1.0 - BELLY_NARROWING * belly;
            }
            if i <= HIP_KNOT {
                s.half_width *= 1.0 + HIP_WIDENING * hipness;
            }
            s
        })
        .collect()
}

/// The `shaped` knots sized so that each level's knot has its girth (hip, waist, chest) and
/// the others follow their levels, centred so that y = 0 at the waist.
fn sized_knots(shaped: &[Section], girths: [f64; 3]) -> Vec<Section> {
    let lambda: [f64; 3] = std::array::from_fn(|l| girths[l] / shaped[LEVEL_KNOTS[l]].perimeter());
    let mut knots: Vec<Section> = shaped
        .iter()
        .zip(REF_KNOTS.iter())
        .map(|(s, r)| s.scaled((0..3).map(|l| r.follows[l] * lambda[l]).sum()))
        .collect();
    let y0 = knots[WAIST_KNOT].centre_y();
    for s in &mut knots {
        s.y_front -= y0;
        s.y_back -= y0;
    }
    knots
}

/// The shoulders: as wide as the shoulder width at the joints, sloping up to the neck, whose
/// base knot is sized from the `head`'s neck.
fn shape_shoulders(knots: &mut [Section], p: &BodyParams, head: &Head) {
    let h = p.height_mm;
    let half_s = 0.5 * p.shoulder_width_mm;
    knots[SHOULDER_JOINT_KNOT].half_width = half_s - SHOULDER_JOINT_INSET * h;
    knots[ACROMION_KNOT].half_width = half_s - ACROMION_INSET * h;
    let (nb, rn) = (head.neck_base, head.r_neck);
    knots[NECK_BASE_KNOT] = Section {
        half_width: NECK_BASE_HALF_WIDTH * rn,
        y_front: nb.y - NECK_BASE_FRONT * rn,
        y_back: nb.y + NECK_BASE_BACK * rn,
        ..knots[NECK_BASE_KNOT]
    };
}

/// The left breast's ellipsoid (centre, semi-axes) on the `chest` knot at `z_chest`, and how far
/// it stands out of the chest wall.
fn design_breast(p: &BodyParams, chest: &Section, z_chest: f64) -> ((DVec3, DVec3), f64) {
    let bust_protrusion = (BUST_BASE_MM + BUST_PER_PROMINENCE_MM * p.bust_prominence)
        * p.chest_girth_mm
        / REF_CHEST_MM;
    let rx = BREAST_RX * chest.half_width;
    let ry = (BREAST_RY * chest.half_width).max(bust_protrusion + BREAST_MIN_DEPTH_MM);
    let x = BREAST_X * chest.half_width;
    let y = chest.front_y_at(x) + ry - bust_protrusion;
    ((DVec3::new(x, y, z_chest), DVec3::new(rx, ry, BREAST_RZ_OF_RX * rx)), bust_protrusion)
}

/// The left buttock's ellipsoid (centre, semi-axes) behind the `hip` knot at `z_hip`.
fn design_buttock(p: &BodyParams, hip: &Section, z_hip: f64) -> (DVec3, DVec3) {
    let (h, crotch) = (p.height_mm, p.leg_length_mm);
    let depth = hip.y_back - hip.y_front;
    let (rx, ry, rz) =
        (BUTTOCK_RX * hip.half_width, BUTTOCK_RY * depth, (z_hip - crotch) + BUTTOCK_ABOVE_HIP * h);
    let y = hip.y_back + BUTTOCK_BEHIND * depth - ry;
    (DVec3::new(BUTTOCK_X * hip.half_width, y, z_hip), DVec3::new(rx, ry, rz))
}

/// The spine's bend and twist between the waist (`z_waist`) and the shoulder joints, and the
/// head's turn about the neck's axis, as `p`'s pose has them.
fn spine_warp(p: &BodyParams, z_waist: f64, head: &Head) -> SpineWarp {
    SpineWarp {
        band: (z_waist, Z_SHOULDER_KNOT * p.height_mm),
        bend: p.pose.spine.lateral_bend_deg.to_radians(),
        twist: p.pose.spine.twist_deg.to_radians(),
        neck_axis: (head.neck_base.x, head.neck_base.y),
        head_turn: p.pose.head_turn_deg.to_radians(),
    }
}

/// Neck and head: neck girth from chest and stature, head size from stature; the neck leans
/// forward and the head sits a little in front of the chest's centre.
fn design_head(p: &BodyParams, chest: &Section) -> Head {
    let h = p.height_mm;
    let kh = (h / REF_HEIGHT).sqrt();
    let r_neck = (0.25 * p.chest_girth_mm + 0.07 * h) / std::f64::consts::TAU;
    let depth = chest.y_back - chest.y_front;
    let neck_base = DVec3::new(0.0, chest.centre_y() + 0.08 * depth, 0.82 * h);
    let cranium_c = DVec3::new(0.0, chest.centre_y() - 0.012 * h, h - 100.0 * kh);
    let neck_top = DVec3::new(0.0, cranium_c.y + 22.0 * kh, 0.875 * h);
    let cranium = (cranium_c, DVec3::new(76.0, 97.0, 100.0) * kh);
    let jaw = (
        DVec3::new(0.0, cranium_c.y - 32.0 * kh, h - 170.0 * kh),
        DVec3::new(56.0, 62.0, 58.0) * kh,
    );
    // The face's front at a height: the foremost of cranium and jaw.
    let front_at = |z: f64| {
        [cranium, jaw]
            .iter()
            .map(|(c, r)| {
                let t = ((z - c.z) / r.z).clamp(-1.0, 1.0);
                c.y - r.y * (1.0 - t * t).sqrt()
            })
            .fold(f64::MAX, f64::min)
    };
    let (z_bridge, z_tip) = (h - 112.0 * kh, h - 148.0 * kh);
    let nose = (
        DVec3::new(0.0, front_at(z_bridge) + 6.0 * kh, z_bridge),
        7.0 * kh,
        DVec3::new(0.0, front_at(z_tip) - 12.0 * kh, z_tip),
        10.0 * kh,
    );
    let ear = (
        DVec3::new(74.0 * kh, cranium_c.y + 8.0 * kh, h - 118.0 * kh),
        DVec3::new(8.0, 15.0, 28.0) * kh,
    );
    Head { neck_base, neck_top, r_neck, cranium, jaw, nose, ear }
}

/// Arm of `side`: shoulder joint from the shoulder width, segment lengths from the stature,
/// thickness from the chest girth; posed by abduction, flexion and elbow flexion.
fn design_arm(p: &BodyParams, side: usize, chest: &Section, head: &Head) -> Arm {
    let h = p.height_mm;
    let sg = SIDE_SIGN[side];
    let pose = if side == 0 { p.pose.left_arm } else { p.pose.right_arm };
    let lift = pose.shoulder_elevation_mm;
    let half_s = 0.5 * p.shoulder_width_mm;
    let y_shoulder = chest.centre_y() + 0.06 * (chest.y_back - chest.y_front);
    let shoulder = DVec3::new(sg * (half_s - 0.018 * h), y_shoulder, 0.792 * h + lift);
    let acromion = DVec3::new(sg * half_s, y_shoulder, Z_ACROMION * h + lift);
    let (r_neck_end, r_shoulder_end) = (0.022 * h, 0.026 * h);
    let trapezius = (
        DVec3::new(sg * 0.9 * head.r_neck, head.neck_base.y, 0.835 * h - r_neck_end),
        DVec3::new(sg * (half_s - r_shoulder_end), y_shoulder, 0.818 * h + lift - r_shoulder_end),
        r_neck_end,
        r_shoulder_end,
    );

    let r_upper = 0.049 * p.chest_girth_mm;
    let r_elbow = 0.6 * r_upper + 0.006 * h;
    let r_forearm = 0.7 * r_upper + 0.006 * h;
    let r_wrist = 0.0095 * h + 0.008 * p.chest_girth_mm;
    let deltoid = (
        shoulder + DVec3::new(sg * 0.2 * r_upper, 0.0, -0.25 * r_upper),
        DVec3::new(0.9, 1.0, 1.0) * r_upper,
    );

    // Rotations: abduction about Y (outwards), flexion about X (forwards), elbow about the
    // upper arm's left-right axis (forearm forwards).
    let upper = DQuat::from_rotation_x(-pose.flexion_deg.to_radians())
        * DQuat::from_rotation_y(-sg * pose.abduction_deg.to_radians());
    let lower = upper * DQuat::from_rotation_x(-pose.elbow_flexion_deg.to_radians());
    let down = DVec3::NEG_Z;
    let elbow = shoulder + upper * down * (0.172 * h);
    let wrist = elbow + lower * down * (0.145 * h);
    let hand_length = 0.105 * h;
    let along = lower * down;
    let fingertip = wrist + along * hand_length;
    let hand_axes = [along, lower * DVec3::NEG_Y, lower * DVec3::new(sg, 0.0, 0.0)];
    Arm {
        acromion,
        trapezius,
        deltoid,
        shoulder,
        elbow,
        wrist,
        fingertip,
        r_upper,
        r_elbow,
        r_forearm,
        r_wrist,
        hand_axes,
        hand_length,
    }
}

/// Leg of `side`: hip joint from the hip girth and crotch height, knee and ankle heights from
/// the crotch height and stature, thickness from the hip girth; abducted in the frontal plane
/// with the ankle kept at its height (the foot stays on the floor).
fn design_leg(p: &BodyParams, side: usize, hip_knot: &Section) -> Leg {
    let h = p.height_mm;
    let hg = p.hip_girth_mm;
    let sg = SIDE_SIGN[side];
    let pose = if side == 0 { p.pose.left_leg } else { p.pose.right_leg };
    let y_hip = hip_knot.y_front + 0.40 * (hip_knot.y_back - hip_knot.y_front);
    let hip = DVec3::new(sg * 0.09 * hg, y_hip, p.leg_length_mm + 0.06 * h);
    let z_knee = 0.615 * p.leg_length_mm;
    let z_ankle = 0.043 * h;
    let reach = (hip.z - z_ankle) * pose.abduction_deg.to_radians().tan();
    let ankle = DVec3::new(hip.x + sg * reach, y_hip - 0.005 * h, z_ankle);
    let knee = hip.lerp(ankle, (hip.z - z_knee) / (hip.z - z_ankle));
    let toe_out = pose.toe_out_deg.to_radians();
    Leg {
        hip,
        knee,
        ankle,
        r_hip: 0.086 * hg,
        r_thigh_mid: 0.077 * hg,
        r_knee: 0.054 * hg,
        r_calf: 0.056 * hg,
        r_ankle: 0.032 * hg,
        foot_forward: DVec3::new(sg * toe_out.sin(), -toe_out.cos(), 0.0),
        foot_lateral: DVec3::new(sg * toe_out.cos(), toe_out.sin(), 0.0),
        foot_length: 0.152 * h,
        foot_width: 0.058 * h * (hg / 1000.0).powf(0.25),
    }
}
