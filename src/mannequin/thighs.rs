//! The thighs' top layers eased into the hips above them.
//!
//! The lowest torso layer (just above the crotch) and the legs' top layers (just below it)
//! are made symmetric each on its own rays: the torso's from the torso's centre, the legs'
//! from each leg's. Where a torso section is not star-shaped from its centre — the gluteal
//! cleft, the groove beside the pubis — its farthest crossing cuts across the hollow, and the
//! torso ring runs up to 10 mm inside the thigh ring 2 mm below it: a step that the band
//! between them can only bridge lying flat (a crease of over 100 degrees, a line across the
//! thighs in a shaded picture). A thigh never sticks out of the hip above it on a body, so
//! where the top leg ring does — beyond the lowest torso ring continued down to it as the body
//! slopes there ([`continued_down`]) — it is pulled in onto that ring; where it lies just inside
//! that ring (continued down everywhere) it is moved onto it ([`SNAP_MM`]); and the layers below
//! follow a smooth fraction of that pull over [`EASE_MM`] of height. Each eased layer reports
//! the girth of its new shape; the torso is not changed.

use super::Layer;
use super::rebuild::closest_on_ring;
use crate::slice::Contour;
use glam::DVec2;

/// The height over which the pull fades out below the crotch (mm): two to three leg layers
/// at the paper's 50 leg layers, so a 10 mm pull slopes at most about 1 in 4.
const EASE_MM: f64 = 40.0;

/// How far from the hips continued down to it the top leg ring is still moved all the way onto
/// them (mm; half the way at 1.5 times this, not at all from twice this). Both are sections of
/// one surface 2 mm apart, but each is made symmetric on its own and scaled back to its own
/// girth about its own centre: on an asymmetric body the hips' ring came out up to 2 mm wider
/// than the thigh's (the generator's random-2), and the 2 mm band between them leaned outward
/// with it, a crease of up to 50 degrees along the join (15 in the median, against 1 along the
/// rings near it). Onto the hips continued down, not the hips themselves: a band standing
/// upright where thigh and hip slope creased as much (6 degrees in the median).
const SNAP_MM: f64 = 4.0;

/// The smooth step from 0 (at `t` <= 0) to 1 (at `t` >= 1), with zero slope at both ends.
fn smoothstep(t: f64) -> f64 {
    let t = t.clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

/// How far each point of the top leg ring `top` must move to meet the torso above it, whose
/// symmetry plane is x = `axis`: to its closest point on `hips` (the most a thigh may stick
/// out) where it lies outside it; where it lies within [`SNAP_MM`] of `surface` (the hips
/// continued down to it everywhere), all the way onto that, and a smoothly smaller part of the
/// way up to twice that; never across the plane.
fn pull(top: &[DVec2], hips: &Contour, surface: &Contour, axis: f64) -> Vec<DVec2> {
    top.iter()
        .map(|&p| {
            if !hips.contains(p) {
                return closest_on_ring(&hips.points, p).2 - p;
            }
            let q = closest_on_ring(&surface.points, p).2;
            let d = q - p;
            if (q.x - axis) * (p.x - axis) > 0.0 {
                d * (1.0 - smoothstep(d.length() / SNAP_MM - 1.0))
            } else {
                DVec2::ZERO
            }
        })
        .collect()
}

/// Eases one leg's layers (bottom to top) into the lowest torso layer `hips` (symmetric about
/// the plane x = `axis`).
fn ease_leg(leg: &mut [Layer], hips: &Contour, surface: &Contour, axis: f64) {
    let Some(top) = leg.last() else { return };
    let (top_z, moves) = (top.z, pull(&top.points, hips, surface, axis));
    if moves.iter().all(|d| *d == DVec2::ZERO) {
        return;
    }
    for layer in leg.iter_mut() {
        let w = smoothstep(1.0 - (top_z - layer.z) / EASE_MM);
        if w == 0.0 {
            continue;
        }
        let ring =
            Contour { points: layer.points.iter().zip(&moves).map(|(p, d)| *p + *d * w).collect() };
        layer.tape_girth = ring.tape_girth();
        layer.contour_length = ring.perimeter();
        layer.points = ring.points;
    }
}

/// The lowest torso layer `hips` continued down to height `z` as the body slopes between it
/// and the layer `above` it (ray by ray: both have the same rays): `everywhere`, or only where
/// it widens downward and elsewhere `hips` itself (the most a thigh may stick out). Pulling the thigh onto the lowest torso ring itself stood the join
/// upright where the thigh and the hip slope inward together (12 degrees on a MakeHuman body):
/// a crease along both its rings, a line across the thighs in a shaded picture.
fn continued_down(hips: &Layer, above: &Layer, z: f64, everywhere: bool) -> Contour {
    let centre = DVec2::from_array(hips.centre);
    let f = (hips.z - z) / (above.z - hips.z);
    let points = hips
        .points
        .iter()
        .zip(&above.points)
        .map(
            |(&p, &q)| {
                if everywhere || (p - q).dot(p - centre) > 0.0 { p + (p - q) * f } else { p }
            },
        )
        .collect();
    Contour { points }
}

/// Eases both legs' top layers into the two lowest torso layers `hips` and `above` (see the
/// module documentation).
pub(super) fn ease(hips: &Layer, above: &Layer, left: &mut [Layer], right: &mut [Layer]) {
    for leg in [left, right] {
        let Some(top_z) = leg.last().map(|top| top.z) else { continue };
        let (outer, surface) =
            (continued_down(hips, above, top_z, false), continued_down(hips, above, top_z, true));
        ease_leg(leg, &outer, &surface, hips.centre[0]);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::regions::Region;
    use std::f64::consts::TAU;

    fn circle(z: f64, radius: impl Fn(DVec2) -> f64) -> Layer {
        let points: Vec<DVec2> = (0..360)
            .map(|k| {
                let d = DVec2::from_angle(TAU * k as f64 / 360.0);
                d * radius(d)
            })
            .collect();
        Layer {
            region: Region::Torso,
            z,
            centre: [0.0, 0.0],
            points,
            input_tape_girth: 0.0,
            input_contour_length: 0.0,
            tape_girth: 0.0,
            contour_length: 0.0,
        }
    }

    #[test]
    fn a_thigh_just_inside_the_hips_meets_them_and_one_well_inside_stays() {
        // Hips of radius 100 mm standing upright; a top leg ring of radius 98 mm, centred on
        // the same point, away from the plane x = -1000.
        let (hips, above) = (circle(1.0, |_| 100.0), circle(7.0, |_| 100.0));
        let surface = continued_down(&hips, &above, -1.0, true);
        let outer = continued_down(&hips, &above, -1.0, false);
        let ring = |r: f64| circle(-1.0, |_| r).points;
        for (p, d) in ring(98.0).iter().zip(pull(&ring(98.0), &outer, &surface, -1000.0)) {
            assert!(((*p + d).length() - 100.0).abs() < 0.01, "{p} moved by {d}");
        }
        let deep = pull(&ring(80.0), &outer, &surface, -1000.0);
        assert!(deep.iter().all(|d| *d == DVec2::ZERO), "a thigh 20 mm inside moved");
    }

    #[test]
    fn the_hips_continue_down_where_they_widen_downward_and_stay_where_they_overhang() {
        // The front half (y < 0) narrows upward from 100 to 94 mm over 6 mm; the back half
        // widens upward from 100 to 106 mm (a buttock overhanging the thigh).
        let hips = circle(1.0, |_| 100.0);
        let above = circle(7.0, |d| if d.y < 0.0 { 94.0 } else { 106.0 });
        let down = continued_down(&hips, &above, -1.0, false);
        for p in &down.points {
            let expected = if p.y < 0.0 { 102.0 } else { 100.0 };
            assert!((p.length() - expected).abs() < 1e-9, "{p}: {} mm out", p.length());
        }
    }
}
