//! The implicit body: the signed distance estimate of the whole surface (negative inside,
//! millimetres), a smooth union of the torso, head, arms and legs designed by
//! [`super::anatomy`], with the torso scaled by a [`Calibration`].

use glam::DVec3;

use super::anatomy::{Anatomy, Arm, Leg, SIDE_SIGN};
use super::primitives::{Aabb, Ellipsoid, RoundCone, Tube, smooth_max, smooth_min};
use super::torso::{Loft, ScaleProfile, Torso};
use super::warp::{Segment, SpineWarp};

/// The value the union starts from: points farther than this from every part read as this.
const FAR_MM: f64 = 200.0;

/// The free parameters calibration tunes so the body matches its girths and crotch height.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Calibration {
    /// Horizontal torso scale at the hip, waist and chest levels.
    pub scale: [f64; 3],
    /// Height of the torso's bottom plane (the crotch before blending).
    pub bottom_z: f64,
}

impl Calibration {
    /// The uncalibrated design: unit scales, bottom plane at the requested crotch height.
    pub fn initial(a: &Anatomy) -> Calibration {
        Calibration { scale: [1.0; 3], bottom_z: a.crotch_height }
    }
}

/// A foot: heel, arch, instep, ball and toes blended, cut flat by the floor.
#[derive(Debug, Clone, PartialEq)]
struct Foot {
    ellipsoids: [Ellipsoid; 4],
    instep: RoundCone,
    blend: f64,
}

impl Foot {
    /// Foot of `leg`, in the leg's foot frame (u forward, v lateral).
    fn new(leg: &Leg) -> Foot {
        let (lf, wf) = (leg.foot_length, leg.foot_width);
        let frame = [leg.foot_forward, leg.foot_lateral, DVec3::Z];
        let part = |u: f64, v: f64, z: f64, radii: DVec3| {
            Ellipsoid::new(leg.foot_point(u * lf, v * wf, z * lf), frame, radii)
        };
        Foot {
            ellipsoids: [
                // Heel, arch (outer side), ball, toes; each reaches a little below the floor,
                // which cuts it flat.
                part(-0.12, 0.0, 0.11, DVec3::new(0.15 * lf, 0.3 * wf, 0.13 * lf)),
                part(0.17, 0.12, 0.055, DVec3::new(0.28 * lf, 0.32 * wf, 0.085 * lf)),
                part(0.47, -0.04, 0.065, DVec3::new(0.17 * lf, 0.5 * wf, 0.085 * lf)),
                part(0.62, -0.08, 0.045, DVec3::new(0.11 * lf, 0.44 * wf, 0.06 * lf)),
            ],
            instep: RoundCone::new(
                leg.ankle,
                0.95 * leg.r_ankle,
                leg.foot_point(0.40 * lf, -0.05 * wf, 0.10 * lf),
                0.09 * lf,
            ),
            blend: 0.08 * lf,
        }
    }

    /// Signed distance estimate; the sole is the plane z = 0.
    fn distance(&self, p: DVec3) -> f64 {
        let mut d = self.instep.distance(p);
        for e in &self.ellipsoids {
            d = smooth_min(d, e.distance(p), self.blend);
        }
        smooth_max(d, -p.z, 6.0)
    }

    /// Bounding box, not below the floor.
    fn bounds(&self) -> Aabb {
        let b = self.ellipsoids.iter().fold(self.instep.bounds(), |b, e| b.union(e.bounds()));
        Aabb { min: b.min.with_z(b.min.z.max(0.0)), max: b.max }
    }

    /// Lower bound of `distance / true distance` outside the foot's parts.
    fn bound_ratio(&self) -> f64 {
        self.ellipsoids.iter().map(|e| e.bound_ratio()).fold(1.0, f64::min)
    }
}

/// The shape of one part of the body.
#[derive(Debug, Clone, PartialEq)]
enum Shape {
    Torso(Box<Torso>),
    Cone(RoundCone),
    Tube(Tube),
    Ellipsoid(Ellipsoid),
    Foot(Box<Foot>),
}

impl Shape {
    /// Signed distance estimate from `p`.
    fn distance(&self, p: DVec3) -> f64 {
        match self {
            Shape::Torso(t) => t.distance(p),
            Shape::Cone(c) => c.distance(p),
            Shape::Tube(t) => t.distance(p),
            Shape::Ellipsoid(e) => e.distance(p),
            Shape::Foot(f) => f.distance(p),
        }
    }
}

/// A part of the union: one shape, or a left-right pair blended with each other first (so
/// the union does not depend on which side comes first and a symmetric pose gives a mirror
/// symmetric body); how wide it blends into what came before; and a lower bound of its value
/// outside each member's box (`ratio * distance to the box - offset`) used to skip far parts.
#[derive(Debug, Clone, PartialEq)]
struct Part {
    members: Vec<(Shape, Aabb)>,
    blend: f64,
    bound_ratio: f64,
    bound_offset: f64,
    /// A point inside each member (seeds for the mesher), as designed.
    inside: Vec<DVec3>,
    /// What the part moves with when the spine bends and twists and the head turns.
    segment: Segment,
    /// Whether it is part of an arm (left out of the torso's girths).
    arm: bool,
}

impl Part {
    /// The part, moving with `segment`.
    fn moving(self, segment: Segment) -> Part {
        Part { segment, ..self }
    }

    /// The part, as part of an arm.
    fn of_arm(self) -> Part {
        Part { arm: true, ..self }
    }

    /// A part of one shape with box `bounds`, a point `inside` it, blending by `blend`; its
    /// value is at least the distance to the box outside it.
    fn single(shape: Shape, bounds: Aabb, inside: DVec3, blend: f64) -> Part {
        Part {
            members: vec![(shape, bounds)],
            blend,
            bound_ratio: 1.0,
            bound_offset: 0.0,
            inside: vec![inside],
            segment: Segment::Trunk,
            arm: false,
        }
    }

    /// A round cone part (see [`RoundCone::new`]).
    fn cone(a: DVec3, ra: f64, b: DVec3, rb: f64, blend: f64) -> Part {
        let c = RoundCone::new(a, ra, b, rb);
        let inside = if ra >= rb { a } else { b };
        Part::single(Shape::Cone(c.clone()), c.bounds(), inside, blend)
    }

    /// A tube part (see [`Tube::new`]).
    fn tube(a: DVec3, b: DVec3, radii: &[(f64, f64)], blend: f64) -> Part {
        let t = Tube::new(a, b, radii);
        Part::single(Shape::Tube(t.clone()), t.bounds(), a, blend)
    }

    /// An ellipsoid part centred at `centre`.
    fn ellipsoid(e: Ellipsoid, centre: DVec3, blend: f64) -> Part {
        Part {
            bound_ratio: e.bound_ratio(),
            ..Part::single(Shape::Ellipsoid(e.clone()), e.bounds(), centre, blend)
        }
    }

    /// The pair of this left part and its right counterpart `right`.
    fn with_mirror(mut self, right: Part) -> Part {
        self.members.extend(right.members);
        self.inside.extend(right.inside);
        self.bound_ratio = self.bound_ratio.min(right.bound_ratio);
        self.bound_offset = self.bound_offset.max(right.bound_offset);
        self
    }

    /// Lower bound of the part's value at `p` (minus infinity inside a member's box).
    fn lower_bound(&self, p: DVec3) -> f64 {
        let nearest = self.members.iter().map(|(_, b)| b.distance(p)).fold(f64::MAX, f64::min);
        if nearest <= 0.0 {
            return f64::NEG_INFINITY;
        }
        let pair_blend = if self.members.len() > 1 { 0.25 * self.blend } else { 0.0 };
        self.bound_ratio * nearest - self.bound_offset - pair_blend
    }

    /// The part's value at `p`: its shape's distance, or the pair blended.
    fn distance(&self, p: DVec3) -> f64 {
        let mut values = self.members.iter().map(|(s, _)| s.distance(p));
        let first = values.next().unwrap_or(FAR_MM);
        values.fold(first, |d, v| smooth_min(d, v, self.blend))
    }
}

/// The body's implicit surface.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct ImplicitBody {
    parts: Vec<Part>,
    loft: Loft,
    /// The spine's and neck's pose.
    pub warp: SpineWarp,
}

impl ImplicitBody {
    /// Assembles the body of `anatomy` with the torso calibrated by `cal`.
    pub fn new(anatomy: &Anatomy, cal: &Calibration) -> ImplicitBody {
        let a = anatomy;
        let loft = Loft::new(&a.knots);
        let mirror = DVec3::new(-1.0, 1.0, 1.0);
        let masses = [(a.breast, 0.6 * a.breast.1.x), (a.buttock, 0.45 * a.buttock.1.x)]
            .map(|((c, r), blend)| {
                let pair = [Ellipsoid::aligned(c, r), Ellipsoid::aligned(c * mirror, r)];
                (pair, blend)
            })
            .to_vec();
        let torso = Torso {
            loft: loft.clone(),
            scale: ScaleProfile {
                z: [a.levels[0], a.levels[1], a.levels[2], a.armpit_knot, a.scale_free_above],
                s: [cal.scale[0], cal.scale[1], cal.scale[2], cal.scale[2], 1.0],
            },
            masses,
            bottom_z: cal.bottom_z,
            bottom_round: 0.03 * a.height,
            top_z: a.torso_top,
            top_round: 0.02 * a.height,
        };
        let waist = loft.at(a.levels[1]);
        let inside = DVec3::new(0.0, waist.centre_y(), a.levels[1]);
        let mut parts = vec![Part {
            bound_ratio: 0.6,
            bound_offset: 2.0 * torso.mass_blend(),
            ..Part::single(
                Shape::Torso(Box::new(torso.clone())),
                torso.bounds(&a.knots),
                inside,
                0.0,
            )
        }];

        let hd = &a.head;
        let mut head =
            vec![Part::cone(hd.neck_base, hd.r_neck, hd.neck_top, 0.92 * hd.r_neck, 25.0)];
        let (cc, cr) = hd.cranium;
        head.push(Part::ellipsoid(Ellipsoid::aligned(cc, cr), cc, 25.0));
        let (jc, jr) = hd.jaw;
        head.push(Part::ellipsoid(Ellipsoid::aligned(jc, jr), jc, 18.0));
        let (na, nra, nb, nrb) = hd.nose;
        head.push(Part::cone(na, nra, nb, nrb, 8.0));
        let nostrils = nb + DVec3::new(0.0, 0.6 * nrb, -0.7 * nrb);
        head.push(Part::ellipsoid(
            Ellipsoid::aligned(nostrils, DVec3::new(1.6, 0.9, 0.8) * nrb),
            nostrils,
            6.0,
        ));
        let (ec, er) = hd.ear;
        let [left_ear, right_ear] = [SIDE_SIGN[0], SIDE_SIGN[1]].map(|sg| {
            let c = ec * DVec3::new(sg, 1.0, 1.0);
            Part::ellipsoid(Ellipsoid::aligned(c, er), c, 4.0)
        });
        head.push(left_ear.with_mirror(right_ear));
        parts.extend(head.into_iter().map(|p| p.moving(Segment::Head)));
        let arms = arm_parts(&a.arms[0]).into_iter().zip(arm_parts(&a.arms[1]));
        parts.extend(arms.map(|(left, right)| left.with_mirror(right).of_arm()));
        let legs = leg_parts(&a.legs[0]).into_iter().zip(leg_parts(&a.legs[1]));
        parts.extend(legs.map(|(left, right)| left.with_mirror(right).moving(Segment::Pelvis)));
        ImplicitBody { parts, loft, warp: a.warp }
    }

    /// Signed distance estimate of the body surface at `p` (negative inside). Parts are
    /// blended in a fixed order; a part is skipped only when its lower bound proves it
    /// cannot change the running value, so the result does not depend on the skipping.
    pub fn value(&self, p: DVec3) -> f64 {
        self.union(p, true)
    }

    /// [`Self::value`] of the body without its arms: what a tape around the torso meets,
    /// even where an arm rests on it.
    pub fn value_without_arms(&self, p: DVec3) -> f64 {
        self.union(p, false)
    }

    /// The union of the parts (with the arms or not) at `p`, each part evaluated where its
    /// segment's warp brings `p` back to the design.
    fn union(&self, p: DVec3, arms: bool) -> f64 {
        let local = |segment: Segment| self.warp.inverse(segment, p);
        let (trunk, head) = (local(Segment::Trunk), local(Segment::Head));
        let mut d = FAR_MM;
        for part in self.parts.iter().filter(|part| arms || !part.arm) {
            let q = match part.segment {
                Segment::Pelvis => p,
                Segment::Trunk => trunk,
                Segment::Head => head,
            };
            if part.lower_bound(q) >= d + part.blend {
                continue;
            }
            d = smooth_min(d, part.distance(q), part.blend);
        }
        d
    }

    /// The centre (x, y) of the torso's section at height `z`: where girth rays start (the
    /// loft's centre line, moved with the spine).
    pub fn torso_centre(&self, z: f64) -> (f64, f64) {
        if self.warp.spine_is_straight() {
            return (0.0, self.loft.at(z).centre_y());
        }
        let axis = |zl: f64| {
            let c = self.loft.at(zl).centre_y();
            self.warp.forward(Segment::Trunk, DVec3::new(0.0, c, zl))
        };
        // The design height whose centre-line point lands at height z (monotone in it).
        let (mut lo, mut hi) = (z - CENTRE_SEARCH_MM, z + CENTRE_SEARCH_MM);
        for _ in 0..60 {
            let mid = 0.5 * (lo + hi);
            if axis(mid).z < z { lo = mid } else { hi = mid }
        }
        let c = axis(0.5 * (lo + hi));
        (c.x, c.y)
    }

    /// One point inside each part: every part of the surface is reached from one of them.
    pub fn interior_points(&self) -> Vec<DVec3> {
        self.parts
            .iter()
            .flat_map(|p| p.inside.iter().map(|&q| self.warp.forward(p.segment, q)))
            .collect()
    }
}

/// How far (mm) a height on the spine's centre line can move with the bend: the band's
/// length times 1 - cos of the largest bend, with margin.
const CENTRE_SEARCH_MM: f64 = 200.0;

/// The parts of an arm: trapezius, deltoid, upper arm, forearm, palm, fingers, thumb.
fn arm_parts(arm: &Arm) -> Vec<Part> {
    let (ta, tb, ra, rb) = arm.trapezius;
    let mut parts = vec![Part::cone(ta, ra, tb, rb, 25.0)];
    let (dc, dr) = arm.deltoid;
    parts.push(Part::ellipsoid(Ellipsoid::aligned(dc, dr), dc, 18.0));
    let (ru, re, rf, rw) = (arm.r_upper, arm.r_elbow, arm.r_forearm, arm.r_wrist);
    parts.push(Part::tube(
        arm.shoulder,
        arm.elbow,
        &[(0.0, ru), (0.45, 0.97 * ru), (0.9, 1.02 * re), (1.0, re)],
        18.0,
    ));
    parts.push(Part::tube(
        arm.elbow,
        arm.wrist,
        &[(0.0, re), (0.22, rf), (0.85, 1.05 * rw), (1.0, rw)],
        12.0,
    ));
    let l = arm.hand_length;
    let [along, across, back] = arm.hand_axes;
    let palm_c = arm.wrist + along * (0.30 * l);
    parts.push(Part::ellipsoid(
        Ellipsoid::new(palm_c, arm.hand_axes, DVec3::new(0.32, 0.24, 0.085) * l),
        palm_c,
        10.0,
    ));
    let fingers_c = arm.wrist + along * (0.70 * l);
    parts.push(Part::ellipsoid(
        Ellipsoid::new(fingers_c, arm.hand_axes, DVec3::new(0.30, 0.21, 0.06) * l),
        fingers_c,
        8.0,
    ));
    parts.push(Part::cone(
        arm.wrist + along * (0.15 * l) + across * (0.2 * l) - back * (0.03 * l),
        0.07 * l,
        arm.wrist + along * (0.5 * l) + across * (0.3 * l) - back * (0.03 * l),
        0.05 * l,
        5.0,
    ));
    parts
}

/// The parts of a leg: one tube from hip to ankle (thigh, knee, calf, ankle), the calf muscle
/// behind it, and the foot.
fn leg_parts(leg: &Leg) -> Vec<Part> {
    let mut parts = Vec::new();
    let knee = leg.hip.distance(leg.knee) / leg.hip.distance(leg.ankle);
    let below = |f: f64| knee + f * (1.0 - knee);
    parts.push(Part::tube(
        leg.hip,
        leg.ankle,
        &[
            (0.0, leg.r_hip),
            (0.45 * knee, leg.r_thigh_mid),
            (0.88 * knee, 1.04 * leg.r_knee),
            (knee, leg.r_knee),
            (below(0.28), leg.r_calf),
            (below(0.8), 1.08 * leg.r_ankle),
            (1.0, leg.r_ankle),
        ],
        40.0,
    ));
    let shank = leg.knee.distance(leg.ankle);
    let calf = leg.knee.lerp(leg.ankle, 0.27) + DVec3::new(0.0, 0.3 * leg.r_calf, 0.0);
    parts.push(Part::ellipsoid(
        Ellipsoid::aligned(
            calf,
            DVec3::new(0.8, 0.75, 0.0) * leg.r_calf + DVec3::Z * (0.22 * shank),
        ),
        calf,
        25.0,
    ));
    let foot = Foot::new(leg);
    let heel = leg.foot_point(-0.12 * leg.foot_length, 0.0, 0.11 * leg.foot_length);
    parts.push(Part {
        bound_ratio: foot.bound_ratio(),
        bound_offset: foot.blend,
        ..Part::single(Shape::Foot(Box::new(foot.clone())), foot.bounds(), heel, 18.0)
    });
    parts
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::params::{BodyParams, Pose};

    fn default_body() -> (Anatomy, ImplicitBody) {
        let a = Anatomy::new(&BodyParams::default());
        let body = ImplicitBody::new(&a, &Calibration::initial(&a));
        (a, body)
    }

    #[test]
    fn inside_outside_at_landmarks() {
        let (a, body) = default_body();
        for z in a.levels {
            let (x, y) = body.torso_centre(z);
            assert!(body.value(DVec3::new(x, y, z)) < -50.0);
        }
        // The head's top is at the stature, the soles on the floor.
        let (cranium, _) = a.head.cranium;
        assert!(body.value(cranium.with_z(a.height - 0.5)) < 0.0);
        assert!(body.value(cranium.with_z(a.height + 0.5)) > 0.0);
        for leg in &a.legs {
            let sole = leg.foot_point(0.2 * leg.foot_length, 0.0, 0.0);
            assert!(body.value(sole.with_z(0.5)) < 0.0);
            assert!(body.value(sole.with_z(-0.5)) > 0.0);
            // The toes point forward (-Y), the heel is behind the ankle.
            let toes = leg.foot_point(0.7 * leg.foot_length, 0.0, 10.0);
            let heel = leg.foot_point(-0.2 * leg.foot_length, 0.0, 20.0);
            assert!(toes.y < leg.ankle.y - 100.0 && body.value(toes) < 0.0);
            assert!(heel.y > leg.ankle.y + 30.0 && body.value(heel) < 0.0);
        }
        // The nose stands out in front of the face.
        let (_, _, tip, r) = a.head.nose;
        assert!(body.value(tip - DVec3::Y * (0.5 * r)) < 0.0);
        assert!(body.value(tip - DVec3::Y * (r + 2.0)) > 0.0);
        assert!(tip.y < a.head.cranium.0.y - a.head.cranium.1.y);
        // Far away: the cap.
        assert_eq!(body.value(DVec3::new(3000.0, 0.0, 0.0)), FAR_MM);
    }

    #[test]
    fn symmetric_pose_gives_a_mirror_symmetric_field() {
        let (a, body) = default_body();
        for i in 0..2000 {
            let f = i as f64;
            let p = DVec3::new(
                (f * 37.7) % 700.0 - 350.0,
                (f * 13.3) % 400.0 - 200.0,
                (f * 7.1) % a.height,
            );
            let mirrored = p * DVec3::new(-1.0, 1.0, 1.0);
            assert!((body.value(p) - body.value(mirrored)).abs() < 1e-9, "{p}");
        }
    }

    #[test]
    fn asymmetric_pose_breaks_the_symmetry() {
        let params = BodyParams { pose: Pose::asymmetric_example(), ..BodyParams::default() };
        let a = Anatomy::new(&params);
        let body = ImplicitBody::new(&a, &Calibration::initial(&a));
        // The raised left arm is out at shoulder height; the right one hangs.
        let left_hand = a.arms[0].wrist;
        assert!(left_hand.z > 0.7 * a.height);
        assert!(body.value(left_hand) < 0.0);
        assert!(body.value(left_hand * DVec3::new(-1.0, 1.0, 1.0)) > 0.0);
    }

    #[test]
    fn skipping_far_parts_does_not_change_the_value() {
        let (a, body) = default_body();
        let exhaustive = |p: DVec3| {
            body.parts.iter().fold(FAR_MM, |d, part| smooth_min(d, part.distance(p), part.blend))
        };
        for i in 0..3000 {
            let f = i as f64;
            let p = DVec3::new(
                (f * 41.3) % 1400.0 - 700.0,
                (f * 17.9) % 600.0 - 300.0,
                (f * 3.7) % (a.height + 100.0),
            );
            assert_eq!(body.value(p), exhaustive(p), "{p}");
        }
    }
}
