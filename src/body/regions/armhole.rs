//! The armhole: where a dress-form maker cuts the arm off the torso — along a plane through
//! the armpit and the shoulder point (acromion), capped flat by an "arm plate". Above the
//! armpit every torso section is clipped to the inner side of both planes, so no torso
//! section holds arm material, while the shoulder keeps its slope up to the shoulder point.
//!
//! The shoulder point is found on the front silhouette's upper edge (the highest surface
//! point at each lateral position), from beside the neck outward to where the edge drops
//! below the armpit or leaves the search window: the shoulder slopes gently, then the edge
//! turns into the arm. The shoulder point is that corner — the sample farthest from the
//! chord between the edge's ends (the "knee" of the curve), as scan software takes the
//! acromion from the front view. It holds for a hanging arm (the edge rounds over the
//! shoulder cap into the arm's side), an A-pose (it bends into the arm's upper side) and a
//! raised arm (the notch where the arm begins, below the chord instead of above it).

use super::BISECTION_MM;
use super::contact::Contact;
use crate::body::mesh::Mesh;
use crate::body::slice::Contour;
use glam::{DVec2, DVec3};
use serde::{Deserialize, Serialize};

/// Lateral sampling step of the silhouette (mm).
const PROFILE_STEP_MM: f64 = 1.0;
/// How far inward of the armpit the shoulder point is looked for (mm): the acromion lies
/// lateral of the armpit in every stance, the neck well inside this.
const SEARCH_INWARD_MM: f64 = 60.0;
/// How far outward of the armpit the shoulder point is looked for (mm): beyond the shoulder
/// cap of the largest adult (the deltoid is 40-60 mm thick).
const SEARCH_OUTWARD_MM: f64 = 150.0;

/// One side's armhole: where a dress form's arm plate cuts the arm off the torso.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Armhole {
    /// The armpit: the lowest point where the arm meets the torso (mm, canonical frame).
    #[serde(rename = "armpit_mm")]
    pub armpit: DVec3,
    /// The shoulder point (acromion): the outer end of the top of the shoulder.
    #[serde(rename = "shoulder_point_mm")]
    pub shoulder_point: DVec3,
    /// Unit normal of the arm plate's plane (through both points), pointing away from the
    /// torso, into the arm.
    pub normal: DVec3,
    /// Where the arm rests on the torso below the armpit, if it does: there the torso is
    /// cut off the arm along the crease between them.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub contact: Option<Contact>,
}

impl Armhole {
    /// The arm plate through `armpit` and `shoulder_point` that contains the body's
    /// front-back direction `front` (so it faces sideways, as a dress form's does); `side` is
    /// +1 for the subject's left (+X), -1 for the right.
    pub fn through(armpit: DVec3, shoulder_point: DVec3, front: DVec3, side: f64) -> Armhole {
        let n = (shoulder_point - armpit).cross(front).normalize_or(DVec3::X);
        let normal = if n.x * side < 0.0 { -n } else { n };
        Armhole { armpit, shoulder_point, normal, contact: None }
    }

    /// Below this height the arm's loop is apart from the torso's: the bottom of the contact
    /// for an arm resting on the torso, else the armpit.
    pub fn arm_apart_below(&self) -> f64 {
        self.contact.map_or(self.armpit.z, |c| c.from)
    }

    /// This armhole, with the arm resting on the torso below the armpit along `contact`.
    pub fn with_contact(self, contact: Contact) -> Armhole {
        Armhole { contact: Some(contact), ..self }
    }

    /// How far `p` lies beyond the arm plate, into the arm (negative on the torso's side).
    /// Above the shoulder point the plate continues straight up, so it never cuts the neck.
    pub fn beyond(&self, p: DVec3) -> f64 {
        let q = p.with_z(p.z.min(self.shoulder_point.z));
        (q - self.armpit).dot(self.normal)
    }

    /// The part of the horizontal loop `c` at height `z` on the torso's side of the plate;
    /// below the armpit the loop is returned whole, or, where the arm rests on the torso,
    /// cut along the contact. The plate cuts from [`BISECTION_MM`] below the armpit: the
    /// armpit is the top of its bisection's last interval, so the arm may have joined the
    /// torso's loop that far below it (a torso layer 0.04 mm below both armpits of the
    /// generator's random-12 held both arms).
    pub fn clip(&self, c: &Contour, z: f64) -> Contour {
        if z < self.armpit.z - BISECTION_MM {
            return match self.contact {
                Some(contact) if z >= contact.from => {
                    c.clip_half_plane(contact.normal, contact.offset)
                }
                _ => c.clone(),
            };
        }
        // In the plane at z: beyond(p) = n.xy . p.xy + (n.z z' - n . armpit) <= 0.
        let zc = z.min(self.shoulder_point.z);
        let offset = self.normal.dot(self.armpit) - self.normal.z * zc;
        c.clip_half_plane(self.normal.truncate(), offset)
    }
}

/// The shoulder point's search on one side: the lateral offsets sampled (mm outward from the
/// torso's centre line, from [`SEARCH_INWARD_MM`] inside the armpit to [`SEARCH_OUTWARD_MM`]
/// outside it, every [`PROFILE_STEP_MM`], on the side's half only).
pub(super) struct ShoulderSearch {
    side: f64,
    centre_x: f64,
    armpit: DVec3,
    offsets: Vec<f64>,
}

impl ShoulderSearch {
    /// The search on `side` (+1 left, -1 right) of the centre line `centre_x`, beside `armpit`.
    pub(super) fn new(side: f64, centre_x: f64, armpit: DVec3) -> ShoulderSearch {
        let u_armpit = side * (armpit.x - centre_x);
        let count = ((SEARCH_INWARD_MM + SEARCH_OUTWARD_MM) / PROFILE_STEP_MM) as usize + 1;
        let offsets = (0..count)
            .map(|k| u_armpit - SEARCH_INWARD_MM + PROFILE_STEP_MM * k as f64)
            .filter(|&u| u > 0.0)
            .collect();
        ShoulderSearch { side, centre_x, armpit, offsets }
    }

    /// The side searched: +1 the subject's left, -1 the right.
    pub(super) fn side(&self) -> f64 {
        self.side
    }

    /// Lateral offset of `p`.
    fn lateral(&self, p: DVec3) -> f64 {
        self.side * (p.x - self.centre_x)
    }

    /// Whether a triangle (its corners) may bear on the search: it reaches the armpit's height
    /// and spans the sampled offsets (with a step's margin). The triangles that do not are
    /// the ones [`Self::shoulder_point`] would pass over, so listing only these changes nothing.
    pub(super) fn may_touch(&self, c: &[DVec3; 3]) -> bool {
        let (Some(&first), Some(&last)) = (self.offsets.first(), self.offsets.last()) else {
            return false;
        };
        let u = c.map(|p| self.lateral(p));
        c.iter().any(|p| p.z >= self.armpit.z)
            && u.iter().any(|&u| u >= first - PROFILE_STEP_MM)
            && u.iter().any(|&u| u <= last + PROFILE_STEP_MM)
    }

    /// The highest surface point at each sampled offset among the triangles of `body` listed
    /// in `near` that reach the armpit's height: the upper edge of the front silhouette, as
    /// (height, y) per offset (`None` where no surface is there).
    fn silhouette_top(&self, body: &Mesh, near: &[u32]) -> Vec<Option<(f64, f64)>> {
        let (us, z_min) = (&self.offsets, self.armpit.z);
        let (u0, step) = (us[0], PROFILE_STEP_MM);
        let higher = |slot: &Option<(f64, f64)>, z: f64| slot.is_none_or(|(top, _)| z > top);
        // In parallel over blocks of triangles, merged in order: the first highest point wins,
        // as in one pass.
        crate::body::mesh::reduce::fold(
            near.len(),
            || vec![None; us.len()],
            |mut top: Vec<Option<(f64, f64)>>, i| {
                let c = body.corners(near[i] as usize);
                if c.iter().all(|p| p.z < z_min) {
                    return top;
                }
                let u = c.map(|p| self.lateral(p));
                let (lo, hi) = (u[0].min(u[1]).min(u[2]), u[0].max(u[1]).max(u[2]));
                let first = ((lo - u0) / step).ceil().max(0.0) as usize;
                let last = (((hi - u0) / step).floor()).min(us.len() as f64 - 1.0);
                if last < first as f64 {
                    return top;
                }
                for (b, slot) in top.iter_mut().enumerate().take(last as usize + 1).skip(first) {
                    let ub = us[b];
                    for k in 0..3 {
                        let (a, e) = ((c[k], u[k]), (c[(k + 1) % 3], u[(k + 1) % 3]));
                        if (a.1 - ub) * (e.1 - ub) > 0.0 || a.1 == e.1 {
                            continue;
                        }
                        let p = a.0.lerp(e.0, (ub - a.1) / (e.1 - a.1));
                        if higher(slot, p.z) {
                            *slot = Some((p.z, p.y));
                        }
                    }
                }
                top
            },
            |mut top, later| {
                for (slot, l) in top.iter_mut().zip(later) {
                    if l.is_some_and(|(z, _)| higher(slot, z)) {
                        *slot = l;
                    }
                }
                top
            },
        )
    }

    /// The shoulder point of `body`, given the neck's height (the silhouette above it is the
    /// head's); `near` lists (in the body's order) at least the triangles that
    /// [`Self::may_touch`] the search.
    pub(super) fn shoulder_point(&self, body: &Mesh, near: &[u32], neck: f64) -> Option<DVec3> {
        let (us, armpit) = (&self.offsets, self.armpit);
        if us.is_empty() {
            return None;
        }
        let top = self.silhouette_top(body, near);
        let point =
            |k: usize| top[k].map(|(z, y)| DVec3::new(self.centre_x + self.side * us[k], y, z));
        // Shoulder samples: on the surface, above the armpit, below the neck.
        let on_shoulder = |k: usize| top[k].is_some_and(|(z, _)| z > armpit.z && z < neck);
        let start = (0..us.len()).find(|&k| on_shoulder(k))?;
        let edge: Vec<usize> = (start..us.len()).take_while(|&k| on_shoulder(k)).collect();
        let (&first, &last) = (edge.first()?, edge.last()?);
        // The corner: the sample farthest from the chord between the edge's ends (the "knee").
        let at = |k: usize| top[k].map(|(z, _)| glam::DVec2::new(us[k], z));
        let (a, b) = (at(first)?, at(last)?);
        let chord = (b - a).normalize_or(glam::DVec2::X);
        let corner = edge
            .iter()
            .filter_map(|&k| at(k).map(|p| (k, chord.perp_dot(p - a).abs())))
            .max_by(|x, y| x.1.total_cmp(&y.1))?;
        point(corner.0)
    }
}

/// The closest pair of points of two loops: (on `a`, on `b`).
pub(super) fn closest_points(a: &Contour, b: &Contour) -> (DVec2, DVec2) {
    let mut best = (f64::INFINITY, DVec2::ZERO, DVec2::ZERO);
    for &p in &a.points {
        for &q in &b.points {
            let d = p.distance_squared(q);
            if d < best.0 {
                best = (d, p, q);
            }
        }
    }
    (best.1, best.2)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_plate_faces_outward_and_clips_beyond_it() {
        // Left side: armpit at x = 150, shoulder point 40 mm further out and 120 mm up.
        let armpit = DVec3::new(150.0, 0.0, 1200.0);
        let shoulder = DVec3::new(190.0, 0.0, 1320.0);
        let left = Armhole::through(armpit, shoulder, DVec3::NEG_Y, 1.0);
        assert!(left.normal.x > 0.0 && left.normal.z < 0.0, "{:?}", left.normal);
        assert!((left.normal.length() - 1.0).abs() < 1e-12);
        assert!(left.beyond(armpit).abs() < 1e-9 && left.beyond(shoulder).abs() < 1e-9);
        assert!(left.beyond(DVec3::new(300.0, 0.0, 1250.0)) > 0.0);
        assert!(left.beyond(DVec3::new(0.0, 0.0, 1500.0)) < 0.0, "never cuts the neck");
        let right = Armhole::through(
            armpit * DVec3::new(-1.0, 1.0, 1.0),
            shoulder * DVec3::new(-1.0, 1.0, 1.0),
            DVec3::NEG_Y,
            -1.0,
        );
        assert!(right.normal.x < 0.0);

        // A square loop 400 mm wide at z = 1260: clipped where the plate crosses that height.
        let square = Contour {
            points: vec![
                DVec2::new(-200.0, -100.0),
                DVec2::new(200.0, -100.0),
                DVec2::new(200.0, 100.0),
                DVec2::new(-200.0, 100.0),
            ],
        };
        let clipped = left.clip(&square, 1260.0);
        let reach = clipped.points.iter().map(|p| p.x).fold(f64::MIN, f64::max);
        assert!((reach - 170.0).abs() < 1e-9, "{reach}");
        assert_eq!(left.clip(&square, 1100.0), square, "below the armpit nothing is cut");
    }

    proptest::proptest! {
        #![proptest_config(proptest::prelude::ProptestConfig::with_cases(128))]

        /// The silhouette from the triangles that may touch the search is the silhouette from
        /// all of them: triangles strewn across both sides, above and below the armpit, at
        /// and beyond the window's ends.
        #[test]
        fn only_the_triangles_that_may_touch_bear_on_the_silhouette(
            corners in proptest::collection::vec(
                (-400.0f64..400.0, -100.0f64..100.0, 1000.0f64..1400.0), 3..120),
            side in proptest::prop_oneof![proptest::strategy::Just(1.0), proptest::strategy::Just(-1.0)],
            pit in (60.0f64..250.0, 1100.0f64..1300.0),
        ) {
            let body = Mesh {
                positions: corners.iter().map(|&(x, y, z)| DVec3::new(x, y, z)).collect(),
                triangles: (0..corners.len() as u32 / 3).map(|t| [3 * t, 3 * t + 1, 3 * t + 2]).collect(),
            };
            let search = ShoulderSearch::new(side, 10.0, DVec3::new(10.0 + side * pit.0, 0.0, pit.1));
            let all: Vec<u32> = (0..body.triangles.len() as u32).collect();
            let near: Vec<u32> =
                all.iter().copied().filter(|&t| search.may_touch(&body.corners(t as usize))).collect();
            proptest::prop_assert_eq!(search.silhouette_top(&body, &near), search.silhouette_top(&body, &all));
        }
    }
}
