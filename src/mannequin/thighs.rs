//! The thighs' top layers eased into the hips above them.
//!
//! The lowest torso layer (just above the crotch) and the legs' top layers (just below it)
//! are made symmetric each on its own rays: the torso's from the torso's centre, the legs'
//! from each leg's. Where a torso section is not star-shaped from its centre — the gluteal
//! cleft, the groove beside the pubis — its farthest crossing cuts across the hollow, and the
//! torso ring runs up to 10 mm inside the thigh ring 2 mm below it: a step that the band
//! between them can only bridge lying flat (a crease of over 100 degrees, a line across the
//! thighs in a shaded picture). The top leg ring and the lowest torso ring are sections of one
//! surface 2 mm apart, so the top leg ring is moved onto the lowest torso ring continued down
//! to it as the body slopes there ([`continued_down`]): where it sticks out of it, and where it
//! lies just inside it ([`SNAP_MM`]; each ring is made symmetric and scaled back to its girth
//! on its own, so on an asymmetric body they part by a millimetre or two); a thigh well inside
//! the hips (the inner thigh beside the crotch) stays. The layers below follow a smooth
//! fraction of that move over [`EASE_MM`] of height. Each eased layer reports
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

/// How far each point of the top leg ring `top` must move to meet `surface`, the hips above
/// it continued down to it (symmetric about the plane x = `axis`): where it lies outside, all
/// the way onto its closest point on `surface`; where it lies inside within [`SNAP_MM`], all
/// the way too, and a smoothly smaller part of the way up to twice that; never across the
/// plane.
fn pull(top: &[DVec2], surface: &Contour, axis: f64) -> Vec<DVec2> {
    top.iter()
        .map(|&p| {
            let q = closest_on_ring(&surface.points, p).2;
            let d = q - p;
            if !surface.contains(p) {
                d
            } else if (q.x - axis) * (p.x - axis) > 0.0 {
                d * (1.0 - smoothstep(d.length() / SNAP_MM - 1.0))
            } else {
                DVec2::ZERO
            }
        })
        .collect()
}

/// Eases one leg's layers (bottom to top) into `surface`, the hips continued down to its top
/// layer (symmetric about the plane x = `axis`).
fn ease_leg(leg: &mut [Layer], surface: &Contour, axis: f64) {
    let Some(top) = leg.last() else { return };
    let (top_z, moves) = (top.z, pull(&top.points, surface, axis));
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
/// and the layer `above` it (ray by ray: both have the same rays). Meeting the lowest torso
/// ring itself stood the join upright where the thigh and the hip slope together (12 degrees
/// on a MakeHuman body, 15 where the hips overhang on a reconstructed scan): a crease along
/// both its rings, a line across the thighs in a shaded picture.
fn continued_down(hips: &Layer, above: &Layer, z: f64) -> Contour {
    let f = (hips.z - z) / (above.z - hips.z);
    let points = hips.points.iter().zip(&above.points).map(|(&p, &q)| p + (p - q) * f).collect();
    Contour { points }
}

/// Eases both legs' top layers into the two lowest torso layers `hips` and `above` (see the
/// module documentation).
pub(super) fn ease(hips: &Layer, above: &Layer, left: &mut [Layer], right: &mut [Layer]) {
    for leg in [left, right] {
        let Some(top_z) = leg.last().map(|top| top.z) else { continue };
        ease_leg(leg, &continued_down(hips, above, top_z), hips.centre[0]);
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
        // Hips of radius 100 mm standing upright; top leg rings centred on the same point,
        // away from the plane x = -1000.
        let (hips, above) = (circle(1.0, |_| 100.0), circle(7.0, |_| 100.0));
        let surface = continued_down(&hips, &above, -1.0);
        let ring = |r: f64| circle(-1.0, |_| r).points;
        for r in [98.0, 103.0] {
            for (p, d) in ring(r).iter().zip(pull(&ring(r), &surface, -1000.0)) {
                assert!(((*p + d).length() - 100.0).abs() < 0.01, "{p} moved by {d}");
            }
        }
        let deep = pull(&ring(80.0), &surface, -1000.0);
        assert!(deep.iter().all(|d| *d == DVec2::ZERO), "a thigh 20 mm inside moved");
    }

    #[test]
    fn the_hips_continue_down_at_their_slope() {
        // The front half (y < 0) narrows upward from 100 to 94 mm over 6 mm; the back half
        // widens upward from 100 to 106 mm (a buttock overhanging the thigh).
        let hips = circle(1.0, |_| 100.0);
        let above = circle(7.0, |d| if d.y < 0.0 { 94.0 } else { 106.0 });
        let down = continued_down(&hips, &above, -1.0);
        for p in &down.points {
            let expected = if p.y < 0.0 { 102.0 } else { 98.0 };
            assert!((p.length() - expected).abs() < 1e-9, "{p}: {} mm out", p.length());
        }
    }
}
