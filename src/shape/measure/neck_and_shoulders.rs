//! The measurements of ISO 8559-1 that run over the neck base, the shoulders and the upper
//! back and chest: neck-base girth, the arc across the shoulders, across back and across
//! front. None of them is a horizontal girth, so each is found from landmarks on the body's
//! profiles and taken along the plane or the stretch of loop those landmarks fix:
//!
//! - **front neck point** (jugular notch): the corner of the front midline profile between
//!   the higher armpit and the neck, the point farthest behind the chord joining the two ends;
//! - **side neck points**: the corner of the front silhouette between each shoulder point and
//!   the side of the neck at the neck level, the point farthest below that chord;
//! - **neck-base girth**: the tape girth of the neck cut by the plane through the front and
//!   both side neck points; the **back neck point** (cervicale) is where that loop lies
//!   farthest back within [`MIDLINE_BAND_MM`] of the centre line;
//! - **across shoulder**: from one shoulder point to the other over the back of the neck
//!   base, a tape along the surface cut by the plane through both shoulder points and the back
//!   neck point;
//! - **across back / across front**: a tape laid horizontally across the back (front) from
//!   armhole to armhole, half way up the armholes (midway between the higher armpit and the
//!   lower shoulder point), between the points where the arm plates (the armhole planes
//!   through armpit and shoulder point, [`crate::body::regions::Armhole`]) meet the back (front):
//!   where the arm joins the torso, as on a dress form, whose across back is measured between
//!   its arm plates. ISO 8559-1 takes it between the armpit folds; a scan shows the folds
//!   only as the hollows of the arm's junction, which an arm held out or resting on the torso
//!   changes, while the plates stay put.

use super::heights_between as heights;
use super::plane::{PlaneLoop, tape_arc};
use crate::body::regions::Armhole;
use crate::body::segmented_body::SegmentedBody;
use crate::body::slice::Contour;
use glam::{DVec2, DVec3};
use serde::Serialize;

/// Half-width of the band around the centre line whose front-most point the front profile
/// follows (mm): as wide as the jugular notch, narrower than the neck.
pub const MIDLINE_BAND_MM: f64 = 15.0;
/// How close to an arm plate a point of the clipped torso loop lies on its cut (mm).
const ON_PLATE_MM: f64 = 0.01;

/// A measurement taken in a plane: the plane (through `origin`, unit `normal`) and the value.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct PlaneMeasure {
    /// A point of the plane inside the loop measured (mm).
    #[serde(rename = "origin_mm")]
    pub origin: DVec3,
    /// The plane's unit normal (pointing up).
    pub normal: DVec3,
    /// What the tape reads (mm).
    #[serde(rename = "length_mm")]
    pub length: f64,
}

/// The neck's and shoulders' landmarks and measurements (see the module documentation).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct NeckAndShoulders {
    /// The front neck point (mm).
    #[serde(rename = "front_neck_point_mm")]
    pub front_neck_point: DVec3,
    /// The side neck points, left then right (mm).
    #[serde(rename = "side_neck_points_mm")]
    pub side_neck_points: [DVec3; 2],
    /// The back neck point (mm).
    #[serde(rename = "back_neck_point_mm")]
    pub back_neck_point: DVec3,
    /// Neck-base girth, in the plane through the front and side neck points.
    pub neck_base: PlaneMeasure,
    /// Across shoulder, in the plane through both shoulder points and the back neck point.
    pub across_shoulder: PlaneMeasure,
    /// The level of across back and across front (mm).
    #[serde(rename = "across_level_mm")]
    pub across_level: f64,
    /// Across back (mm; NaN where a fold is missing).
    #[serde(rename = "across_back_mm")]
    pub across_back: f64,
    /// Across front (mm; NaN where a fold is missing).
    #[serde(rename = "across_front_mm")]
    pub across_front: f64,
}

/// The point of `profile` farthest from the chord between its ends on the `inside` side: the
/// corner of a profile that turns there (the first end for a profile without one).
fn corner(profile: &[DVec2], inside: DVec2) -> Option<DVec2> {
    let (&a, &b) = (profile.first()?, profile.last()?);
    let chord = (b - a).normalize_or(DVec2::Y);
    let sign = chord.perp_dot(inside).signum();
    let depth = |p: DVec2| sign * chord.perp_dot(p - a);
    profile.iter().copied().max_by(|p, q| depth(*p).total_cmp(&depth(*q)))
}

/// The torso's midline profile from `from` to `to`: at each level the front-most (`front`) or
/// back-most point within [`MIDLINE_BAND_MM`] of the centre line, as (y, z).
pub(super) fn midline_profile(body: &SegmentedBody, from: f64, to: f64, front: bool) -> Vec<DVec2> {
    let zs = heights(from, to);
    let cx = body.landmarks().centre_x;
    let sign = if front { -1.0 } else { 1.0 };
    zs.iter()
        .zip(body.torso_sections(&zs))
        .filter_map(|(&z, c)| {
            let y = c?
                .points
                .into_iter()
                .filter(|p| (p.x - cx).abs() <= MIDLINE_BAND_MM)
                .map(|p| sign * p.y)
                .reduce(f64::max)?;
            Some(DVec2::new(sign * y, z))
        })
        .collect()
}

/// The side neck point on `side` (+1 the subject's left, -1 the right): the corner of the
/// front silhouette (the torso's outermost x at each level) between the `shoulder_point` and
/// the `neck` level.
fn side_neck_point(body: &SegmentedBody, shoulder_point: DVec3, side: f64) -> Option<DVec3> {
    let m = body.landmarks();
    let zs = heights(shoulder_point.z, m.neck);
    // (outward distance from the centre line, z) and the y of that outermost point.
    let silhouette: Vec<(DVec2, f64)> = zs
        .iter()
        .zip(body.torso_sections(&zs))
        .filter_map(|(&z, c)| {
            let p = c?.points.into_iter().max_by(|a, b| (side * a.x).total_cmp(&(side * b.x)))?;
            Some((DVec2::new(side * (p.x - m.centre_x), z), p.y))
        })
        .collect();
    let profile: Vec<DVec2> = silhouette.iter().map(|s| s.0).collect();
    let c = corner(&profile, DVec2::NEG_Y)?;
    let y = silhouette.iter().find(|s| s.0 == c)?.1;
    Some(DVec3::new(m.centre_x + side * c.x, y, c.y))
}

/// Unit normal of the plane through `a`, `b` and `c`, pointing up.
fn normal_through(a: DVec3, b: DVec3, c: DVec3) -> DVec3 {
    let n = (b - a).cross(c - a).normalize_or(DVec3::Z);
    if n.z < 0.0 { -n } else { n }
}

/// Across back and across front of the horizontal `torso` loop at height `z`, clipped by both
/// `armholes` (left, right): the tape over the back (+Y) and over the front between the ends
/// of the plates' cuts; NaN where a plate does not cut the loop.
pub fn across_back_and_front(torso: &Contour, z: f64, armholes: [&Armhole; 2]) -> (f64, f64) {
    let ends = |armhole: &Armhole| {
        let cut: Vec<DVec2> = (torso.points.iter().copied())
            .filter(|p| armhole.beyond(p.extend(z)).abs() <= ON_PLATE_MM)
            .collect();
        let front = cut.iter().copied().min_by(|a, b| a.y.total_cmp(&b.y))?;
        let back = cut.iter().copied().max_by(|a, b| a.y.total_cmp(&b.y))?;
        Some((front, back))
    };
    let (Some(left), Some(right)) = (ends(armholes[0]), ends(armholes[1])) else {
        return (f64::NAN, f64::NAN);
    };
    let extreme = |sign: f64| {
        (torso.points.iter().copied()).max_by(|a, b| (sign * a.y).total_cmp(&(sign * b.y)))
    };
    let across = |from: DVec2, to: DVec2, sign: f64| {
        extreme(sign).map_or(f64::NAN, |through| tape_arc(torso, from, to, through))
    };
    (across(left.1, right.1, 1.0), across(left.0, right.0, -1.0))
}

/// The neck's and shoulders' measurements of `body`; `None` where a landmark cannot be found
/// (no torso loops between the armpits and the neck).
pub fn neck_and_shoulders(body: &SegmentedBody) -> Option<NeckAndShoulders> {
    let m = body.landmarks();
    let mesh = body.mesh();
    let front = midline_profile(body, m.armpit(), m.neck, true);
    let f = corner(&front, DVec2::X)?;
    let front_neck_point = DVec3::new(m.centre_x, f.x, f.y);
    let (lsp, rsp) = (m.left_armhole.shoulder_point, m.right_armhole.shoulder_point);
    let side_neck_points = [side_neck_point(body, lsp, 1.0)?, side_neck_point(body, rsp, -1.0)?];

    let [sl, sr] = side_neck_points;
    let normal = normal_through(front_neck_point, sl, sr);
    let origin = 0.5 * (sl + sr);
    let neck = PlaneLoop::around(mesh, origin, normal)?;
    let back_neck_point = (neck.contour.points.iter().map(|&p| neck.to_body(p)))
        .filter(|p| (p.x - m.centre_x).abs() <= MIDLINE_BAND_MM)
        .max_by(|a, b| a.y.total_cmp(&b.y))?;
    let neck_base = PlaneMeasure { origin, normal, length: neck.contour.tape_girth() };

    let normal = normal_through(lsp, rsp, back_neck_point);
    let origin = 0.5 * (lsp + rsp);
    let over = PlaneLoop::around(mesh, origin, normal)?;
    let length = tape_arc(
        &over.contour,
        over.to_plane(lsp),
        over.to_plane(rsp),
        over.to_plane(back_neck_point),
    );
    let across_shoulder = PlaneMeasure { origin, normal, length };

    let across_level = 0.5 * (m.armpit() + lsp.z.min(rsp.z));
    let torso = body.torso_sections(&[across_level]).pop().flatten()?;
    let (across_back, across_front) =
        across_back_and_front(&torso, across_level, [&m.left_armhole, &m.right_armhole]);
    Some(NeckAndShoulders {
        front_neck_point,
        side_neck_points,
        back_neck_point,
        neck_base,
        across_shoulder,
        across_level,
        across_back,
        across_front,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::TAU;

    #[test]
    fn across_back_runs_over_the_back_between_the_arm_plates() {
        // A round torso of radius 150 mm, its arm plates upright at x = +-120 mm: across back
        // is the arc between the cuts, r (pi - 2 acos(120 / r)) = 2 r asin(120 / r), and so
        // is across front.
        let r = 150.0;
        let plate = |side: f64| {
            let armpit = DVec3::new(side * 120.0, 0.0, 1000.0);
            Armhole::through(armpit, armpit + DVec3::Z * 200.0, DVec3::NEG_Y, side)
        };
        let (left, right) = (plate(1.0), plate(-1.0));
        let z = 1100.0;
        let circle = Contour {
            points: (0..36000).map(|k| DVec2::from_angle(TAU * k as f64 / 36000.0) * r).collect(),
        };
        let torso = right.clip(&left.clip(&circle, z), z);
        let (back, front) = across_back_and_front(&torso, z, [&left, &right]);
        let arc = r * 2.0 * (120.0 / r).asin();
        assert!((back - arc).abs() < 0.01, "across back {back:.3}, the arc {arc:.3}");
        assert!((front - arc).abs() < 0.01, "across front {front:.3}, the arc {arc:.3}");
        // A plate that misses the loop: nothing to measure between.
        let wide = DVec3::new(400.0, 0.0, 1000.0);
        let wide = Armhole::through(wide, wide + DVec3::Z * 200.0, DVec3::NEG_Y, 1.0);
        let (b, f) = across_back_and_front(&torso, z, [&wide, &right]);
        assert!(b.is_nan() && f.is_nan());
    }

    #[test]
    fn a_profile_corner_is_the_point_farthest_inside_its_chord() {
        // An L: the chest front rising and receding, then the neck straight up.
        let profile: Vec<DVec2> = (0..=10)
            .map(|k| DVec2::new(-120.0 + 6.0 * k as f64, 1300.0 + 13.0 * k as f64))
            .chain((1..=10).map(|k| DVec2::new(-60.0, 1430.0 + 12.0 * k as f64)))
            .collect();
        assert_eq!(corner(&profile, DVec2::X), Some(DVec2::new(-60.0, 1430.0)));
    }
}
