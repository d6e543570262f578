//! The legs' stance: how the mannequin's legs stand below the crotch.
//!
//! A customer stands as they like, feet apart or one foot forward; a dress form's legs hang
//! straight and parallel. With [`LegStance::Straight`] (the default) each leg's axis — the
//! least-squares line through its layers' centres against height, as a leg's abduction is
//! measured — is made vertical by a shear: every horizontal ring of the leg (its layers and
//! the mesh's rings between them) is moved sideways and front to back, its shape and girth
//! unchanged, by the amount that cancels the axis's lean. The shear fades in below the legs'
//! top ring over [`BEND_MM`] (the lean turned off smoothly, [`turned_depth`]), so the top
//! ring, the crotch join, the thighs' easing into the hips ([`super::thighs`]) and the torso
//! are untouched: the crotch height (the inseam) and the hip girth stay as they are. The leg
//! keeps its own shape about its axis (the knee, the calf).
//!
//! Straightening a splayed stance brings the knees and ankles towards the symmetry plane; no
//! ring is moved closer to the plane than the legs' top rings are (where a standing body's
//! thighs are closest), nor than it was, so the legs never run into each other
//! ([`straighten`]). [`LegStance::AsScanned`] keeps the body's own stance made symmetric.

use super::Layer;
use glam::DVec2;

/// How the mannequin's legs stand.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum LegStance {
    /// Parallel and vertical, as a dress form's legs hang: each leg's axis made vertical below
    /// the crotch, the inseam kept. The default.
    #[default]
    Straight,
    /// As the customer stood, made symmetric: the mean of the left leg's direction and the
    /// right leg's mirrored one.
    AsScanned,
}

impl LegStance {
    /// Both stances.
    pub const ALL: [LegStance; 2] = [LegStance::Straight, LegStance::AsScanned];

    /// The stance's name: `straight` or `as-scanned` (as the command line spells it).
    pub fn name(self) -> &'static str {
        match self {
            LegStance::Straight => "straight",
            LegStance::AsScanned => "as-scanned",
        }
    }
}

/// The height below the legs' top ring over which the lean is turned off (mm). Longer is a
/// gentler bend (a 10-degree lean turned over 80 mm bends the thigh's side by a degree every
/// 8 mm); it stays within the legs' fine mesh rings near the crotch (100 mm,
/// `layers::FINE_DEPTH_MM`), which sample the bend, and above the reference form's thigh ring
/// (102 mm below the crotch on the demo's customer), which meets a thigh already hanging
/// straight.
const BEND_MM: f64 = 80.0;

/// How far (mm) a ring `t` mm below the legs' top ring is moved along the lean per unit of
/// lean (mm per mm of height): the integral of `smoothstep(τ / BEND_MM)` from 0 to `t`. Zero
/// with zero slope at the top; below [`BEND_MM`] it grows one for one with the depth, which
/// cancels the lean.
fn turned_depth(t: f64) -> f64 {
    let s = (t / BEND_MM).clamp(0.0, 1.0);
    BEND_MM * (s.powi(3) - 0.5 * s.powi(4)) + (t - BEND_MM).max(0.0)
}

/// The least-squares lean of the centres `(height, centre)`: the change of the centre per mm
/// of height (x and y).
fn lean(centres: &[(f64, DVec2)]) -> DVec2 {
    let n = centres.len() as f64;
    let mz = centres.iter().map(|(z, _)| z).sum::<f64>() / n;
    let mc = centres.iter().map(|(_, c)| *c).sum::<DVec2>() / n;
    let szz: f64 = centres.iter().map(|(z, _)| (z - mz).powi(2)).sum();
    let szc: DVec2 = centres.iter().map(|(z, c)| (*c - mc) * (z - mz)).sum();
    if szz > 0.0 { szc / szz } else { DVec2::ZERO }
}

/// How far the ring `points` reaches towards the plane x = `axis` from its side `side` (1 for
/// the left, -1 for the right): its least distance from the plane (negative across it).
fn clearance(points: &[DVec2], axis: f64, side: f64) -> f64 {
    points.iter().map(|p| side * (p.x - axis)).fold(f64::INFINITY, f64::min)
}

/// Stands one leg's rings (bottom to top; `is_layer` flags its layers, whose centres give its
/// axis) straight on its side of the symmetry plane x = `axis` (see the module
/// documentation). A ring the shear would bring closer to the plane than both the top ring
/// and its own scanned place is moved back out to the nearer of the two.
pub(super) fn straighten(leg: &mut [Layer], is_layer: &[bool], axis: f64) {
    let centres: Vec<(f64, DVec2)> = leg
        .iter()
        .zip(is_layer)
        .filter(|(_, layer)| **layer)
        .map(|(ring, _)| (ring.z, DVec2::from_array(ring.centre)))
        .collect();
    let Some(top) = leg.last() else { return };
    if centres.len() < 2 {
        return;
    }
    let slope = lean(&centres);
    let side = if top.centre[0] >= axis { 1.0 } else { -1.0 };
    let (top_z, top_clearance) = (top.z, clearance(&top.points, axis, side));
    for ring in leg.iter_mut() {
        let mut shift = slope * turned_depth(top_z - ring.z);
        let before = clearance(&ring.points, axis, side);
        let short = before.min(top_clearance) - (before + side * shift.x);
        if short > 0.0 {
            shift.x += side * short;
        }
        ring.points.iter_mut().for_each(|p| *p += shift);
        ring.centre = (DVec2::from_array(ring.centre) + shift).to_array();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::body::regions::Region;
    use crate::shape::mannequin::smoothstep;
    use std::f64::consts::TAU;

    /// A round leg ring of `radius` about `centre` at height `z`.
    fn ring(z: f64, centre: DVec2, radius: f64) -> Layer {
        let points: Vec<DVec2> =
            (0..72).map(|k| centre + DVec2::from_angle(TAU * k as f64 / 72.0) * radius).collect();
        Layer {
            region: Region::LeftLeg,
            z,
            centre: centre.to_array(),
            points,
            input_tape_girth: 0.0,
            input_contour_length: 0.0,
            tape_girth: 0.0,
            contour_length: 0.0,
        }
    }

    /// A left leg from the ankle (z = 100) to the top ring (z = 800), leaning `lean` (x and y
    /// per mm of height), its top centre 100 mm left of the plane x = 0, narrowing from 80 mm
    /// at the top to 40 at the ankle, in rings 10 mm apart.
    fn leaning(lean: DVec2) -> Vec<Layer> {
        (0..=70)
            .map(|k| {
                let z = 100.0 + 10.0 * k as f64;
                ring(
                    z,
                    DVec2::new(100.0, 0.0) + lean * (z - 800.0),
                    40.0 + 40.0 * (z - 100.0) / 700.0,
                )
            })
            .collect()
    }

    #[test]
    fn a_leaning_leg_hangs_straight_below_the_bend_and_keeps_its_top() {
        // Feet 10 degrees out and 5 degrees forward (-Y).
        let lean = DVec2::new(-(10.0_f64.to_radians().tan()), 5.0_f64.to_radians().tan());
        let mut leg = leaning(lean);
        let before = leg.clone();
        let all = vec![true; leg.len()];
        straighten(&mut leg, &all, 0.0);
        let top = leg.len() - 1;
        assert_eq!(leg[top].points, before[top].points, "the top ring stays");
        let below: Vec<DVec2> = leg
            .iter()
            .filter(|r| r.z <= 800.0 - BEND_MM)
            .map(|r| DVec2::from_array(r.centre))
            .collect();
        for c in &below {
            assert!(c.distance(below[0]) < 1e-9, "{c} against {}", below[0]);
        }
        for (a, b) in leg.iter().zip(&before) {
            let shift = DVec2::from_array(a.centre) - DVec2::from_array(b.centre);
            for (p, q) in a.points.iter().zip(&b.points) {
                assert!((*p - *q - shift).length() < 1e-9, "each ring only moves with its centre");
            }
        }
        // Smooth at the top: the ring 10 mm below it moves by a hair (a 10-degree lean turned
        // off in full there would move it 1.8 mm).
        let moved =
            |k: usize| DVec2::from_array(leg[k].centre) - DVec2::from_array(before[k].centre);
        assert!(moved(top - 1).length() < 0.05, "{}", moved(top - 1));
    }

    #[test]
    fn knock_knees_never_cross_the_plane() {
        // A straight leg whose knee (z = 450) reaches in to 5 mm from the plane, leaning 10
        // degrees inward: straightened, the lower leg would swing across the plane.
        let lean = DVec2::new(10.0_f64.to_radians().tan(), 0.0);
        let mut leg = leaning(lean);
        for r in &mut leg {
            let inward = 60.0 * (-((r.z - 450.0) / 80.0).powi(2)).exp();
            r.points.iter_mut().for_each(|p| p.x -= inward);
            r.centre[0] -= inward;
        }
        let floor: Vec<f64> = leg
            .iter()
            .map(|r| clearance(&r.points, 0.0, 1.0).min(clearance(&leg[70].points, 0.0, 1.0)))
            .collect();
        let all = vec![true; leg.len()];
        straighten(&mut leg, &all, 0.0);
        for (r, f) in leg.iter().zip(floor) {
            assert!(clearance(&r.points, 0.0, 1.0) >= f - 1e-9, "at {}", r.z);
        }
    }

    #[test]
    fn the_bend_turns_the_lean_off_smoothly() {
        assert_eq!(turned_depth(0.0), 0.0);
        assert!((turned_depth(BEND_MM) - 0.5 * BEND_MM).abs() < 1e-12);
        let slope = |t: f64| (turned_depth(t + 1e-6) - turned_depth(t - 1e-6)) / 2e-6;
        assert!(slope(1e-3).abs() < 1e-6 && (slope(BEND_MM) - 1.0).abs() < 1e-6);
        assert!((slope(0.5 * BEND_MM) - smoothstep(0.5)).abs() < 1e-6);
    }
}
