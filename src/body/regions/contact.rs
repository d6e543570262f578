//! An arm resting on the torso: where the arm touches the torso below its armpit, the two
//! are one loop in the sections, joined by a narrow neck (the crease where arm and torso
//! press together). Going up from where the loops first join, the neck stays narrow over
//! the contact and opens into the armpit's hollow above it; ISO 8559-1 places the armpit at
//! the top of that contact (the lower end of the armpit folds), not at its bottom.
//!
//! The neck is measured across the line from the torso's centre to the arm's (both taken
//! on the last level where the arm is apart): at each position along that line, the width
//! of the loop across it, through the line; the neck is the narrowest such width between
//! the torso and the arm's centre. An A-posed arm's neck opens within a few millimetres of
//! the join (the armpit is a saddle), so there the armpit stays where the loops join; a
//! resting arm's opens slowly, over the height of the contact, and below the armpit the
//! torso is cut off the arm along the neck ([`Contact`]).

use crate::body::slice::Contour;
use glam::DVec2;
use serde::{Deserialize, Serialize};

/// How far the neck between arm and torso must have opened, as a fraction of the arm's
/// depth across it, for a level to lie above the contact. Calibrated on the sim generator's
/// customers (20 per stance, tests/segmentation_stances.rs): at 0.25 the armpits of arms
/// resting on the torso lie -9 to +5 mm from the generator's design armpits (where the loops
/// join, up to 17 mm low), A-posed arms' -4 to +2.4 mm (at the join, -4 to 0 mm); 0.2 leaves
/// resting armpits up to 15 mm low, 0.3 and 0.35 move A-posed ones 3.5 and 5 mm up.
pub const NECK_OPEN_FRACTION: f64 = 0.25;
/// Spacing of the positions along the torso-to-arm line where the neck's width is taken (mm).
const NECK_STEP_MM: f64 = 1.0;
/// How far inward of the arm's centre the neck is looked for, in arm half-depths: the neck
/// lies at the arm's inner surface (one half-depth), blended a little further in.
const NECK_SEARCH_HALF_DEPTHS: f64 = 1.5;

/// Where an arm rests on the torso below its armpit: between `from` and the armpit, the
/// torso's loop is cut along the neck, the vertical plane `normal . p = offset` (the torso
/// keeps `normal . p <= offset`; `normal` points from the torso into the arm).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Contact {
    /// Where the arm's loop first joins the torso's (mm): the bottom of the contact.
    #[serde(rename = "from_mm")]
    pub from: f64,
    /// Unit normal of the cut (horizontal), from the torso into the arm.
    pub normal: DVec2,
    /// The cut's offset along `normal` (mm).
    #[serde(rename = "offset_mm")]
    pub offset: f64,
}

/// The line across which the neck between the torso and a resting arm is measured, from the
/// loops of both on the last level where they are apart.
#[derive(Debug, Clone, Copy)]
pub(super) struct NeckGauge {
    /// The torso's centroid.
    origin: DVec2,
    /// Unit direction from the torso's centroid to the arm's.
    along: DVec2,
    /// Distance from the torso's centroid to the arm's (mm).
    reach: f64,
    /// The arm's depth across `along` (mm).
    pub depth: f64,
}

/// The neck of one loop: its width across the gauge line, and the middle of that width.
#[derive(Debug, Clone, Copy)]
pub(super) struct Neck {
    pub width: f64,
    pub centre: DVec2,
}

impl NeckGauge {
    /// The gauge between the `torso`'s loop and the `arm`'s, apart on the same level.
    pub fn between(torso: &Contour, arm: &Contour) -> NeckGauge {
        let origin = torso.centroid();
        let to_arm = arm.centroid() - origin;
        let along = to_arm.normalize_or(DVec2::X);
        let across = along.perp();
        let spread = |f: &dyn Fn(DVec2) -> f64| {
            let (lo, hi) = arm
                .points
                .iter()
                .map(|&p| f(p))
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| (lo.min(v), hi.max(v)));
            (hi - lo).max(0.0)
        };
        NeckGauge { origin, along, reach: to_arm.length(), depth: spread(&|p| p.dot(across)) }
    }

    /// Whether `neck` has opened past the contact ([`NECK_OPEN_FRACTION`] of the arm's depth).
    pub fn is_open(&self, neck: Option<Neck>) -> bool {
        neck.is_none_or(|n| n.width >= NECK_OPEN_FRACTION * self.depth)
    }

    /// The narrowest width of `merged` (the torso's loop with the arm joined) across the
    /// gauge line, between the torso's centre and the arm's; `None` where the line does not
    /// pass through the loop there.
    pub fn neck(&self, merged: &Contour) -> Option<Neck> {
        let start = self.reach - NECK_SEARCH_HALF_DEPTHS * 0.5 * self.depth;
        let count = ((self.reach - start) / NECK_STEP_MM).floor() as usize + 1;
        (0..count)
            .filter_map(|k| self.width_at(merged, start + NECK_STEP_MM * k as f64))
            .min_by(|a, b| a.width.total_cmp(&b.width))
    }

    /// The width of `merged` across the gauge line at distance `s` along it: the span
    /// between the loop's crossings of the perpendicular there that holds the line.
    fn width_at(&self, merged: &Contour, s: f64) -> Option<Neck> {
        let across = self.along.perp();
        let local = |p: DVec2| {
            let d = p - self.origin;
            (d.dot(self.along), d.dot(across))
        };
        let mut crossings: Vec<f64> = merged
            .edges()
            .filter_map(|(a, b)| {
                let ((sa, va), (sb, vb)) = (local(a), local(b));
                ((sa - s) * (sb - s) < 0.0).then(|| va + (vb - va) * (s - sa) / (sb - sa))
            })
            .collect();
        crossings.sort_by(f64::total_cmp);
        let pair = crossings.windows(2).find(|w| w[0] <= 0.0 && 0.0 <= w[1])?;
        let centre = self.origin + self.along * s + across * (0.5 * (pair[0] + pair[1]));
        Some(Neck { width: pair[1] - pair[0], centre })
    }

    /// The cut along `neck` (on a level inside the contact) for a contact from `from` up.
    pub fn contact(&self, neck: &Neck, from: f64) -> Contact {
        Contact { from, normal: self.along, offset: self.along.dot(neck.centre) }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn circle(centre: DVec2, radius: f64) -> Contour {
        let points = (0..64)
            .map(|k| {
                let t = std::f64::consts::TAU * k as f64 / 64.0;
                centre + radius * DVec2::new(t.cos(), t.sin())
            })
            .collect();
        Contour { points }
    }

    #[test]
    fn the_neck_of_a_dumbbell_is_its_bridge() {
        // Torso: a 100 mm circle at the origin; arm: a 40 mm circle 140 mm out (+X).
        let gauge =
            NeckGauge::between(&circle(DVec2::ZERO, 100.0), &circle(DVec2::new(140.0, 0.0), 40.0));
        assert!((gauge.depth - 80.0).abs() < 0.5, "{}", gauge.depth);

        // Merged: the two joined by a bridge 12 mm wide (a contact), then 40 mm (open).
        let neck = gauge.neck(&Contour { points: dumbbell(6.0) }).expect("a neck");
        assert!((neck.width - 12.0).abs() < 1e-6, "{}", neck.width);
        assert!(neck.centre.y.abs() < 1e-6 && neck.centre.x > 95.0 && neck.centre.x < 102.0);
        assert!(!gauge.is_open(Some(neck)), "12 of 80 mm is a contact");
        let wide = gauge.neck(&Contour { points: dumbbell(20.0) }).expect("a neck");
        assert!(gauge.is_open(Some(wide)), "40 of 80 mm is open: {}", wide.width);
    }

    /// A 100 mm torso circle and a 40 mm arm circle 140 mm out, joined by a bridge
    /// `half` mm either side of the x axis (counter-clockwise).
    fn dumbbell(half: f64) -> Vec<DVec2> {
        let (torso_x, arm_x) =
            ((100f64 * 100.0 - half * half).sqrt(), 140.0 - (40f64 * 40.0 - half * half).sqrt());
        let arc = |centre: DVec2, radius: f64, from: f64, to: f64| {
            (0..=48).map(move |k| {
                let t = from + (to - from) * k as f64 / 48.0;
                centre + radius * DVec2::new(t.cos(), t.sin())
            })
        };
        let a_t = (half / 100.0).asin();
        let a_a = (half / 40.0).asin();
        let pi = std::f64::consts::PI;
        let mut out: Vec<DVec2> = arc(DVec2::ZERO, 100.0, a_t, 2.0 * pi - a_t).collect();
        out.push(DVec2::new(torso_x, -half));
        out.push(DVec2::new(arm_x, -half));
        out.extend(arc(DVec2::new(140.0, 0.0), 40.0, -pi + a_a, pi - a_a));
        out.push(DVec2::new(arm_x, half));
        out.push(DVec2::new(torso_x, half));
        out
    }
}
