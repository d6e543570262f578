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
//! fraction of that move over [`EASE_MM`] of height, and leave the hips at their slope,
//! turning back to the thigh's own over the same height ([`ease_leg`]). Each eased layer reports
//! the girth of its new shape; the torso is not changed.

use super::rebuild::closest_on_ring;
use super::{Layer, smoothstep};
use crate::body::slice::Contour;
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

/// The largest change of the thigh's slope at its top (mm of horizontal change per mm of
/// depth: tan 30 degrees). Next to the crotch the hips' slope between their two lowest layers
/// turns sharply towards the plane, and followed in full the thighs crossed it (the crotch
/// 13-15 mm lower, 464-746 self-intersecting pairs on the MakeHuman bodies); at tan 40 degrees
/// the turn back to the thigh's own slope creased the MakeHuman base's thigh 8.1 degrees more
/// than further down; at tan 15 degrees the legs' top ring kept half its crease.
const MAX_TURN: f64 = 0.58;

/// Within this distance of the symmetry plane (mm) the thigh keeps more and more of its own
/// slope at its top, all of it at the plane: the inner thighs meet there in the crotch's
/// saddle, which the hips above it do not continue.
const BESIDE_PLANE_MM: f64 = 30.0;

/// Where each point of the top leg ring `top` must move to meet `surface`, the hips above it
/// continued down to it (symmetric about the plane x = `axis`): where it lies outside, all the
/// way onto its closest point on `surface`; where it lies inside within [`SNAP_MM`], all the
/// way too, and a smoothly smaller part of the way up to twice that; never across the plane.
fn pull(top: &[DVec2], surface: &Contour, axis: f64) -> Vec<Pull> {
    top.iter()
        .map(|&p| {
            let (edge, along, q) = closest_on_ring(&surface.points, p);
            let d = q - p;
            let share = if !surface.contains(p) {
                1.0
            } else if (q.x - axis) * (p.x - axis) > 0.0 {
                1.0 - smoothstep(d.length() / SNAP_MM - 1.0)
            } else {
                0.0
            };
            Pull { to: d * share, share, edge, along }
        })
        .collect()
}

/// How one point of the top leg ring meets the hips: its move, the share of the way to the
/// hips it moves (0 to 1), and the point of the hips it moves towards (on the edge from point
/// `edge` of the hips' ring, at fraction `along` of it).
struct Pull {
    to: DVec2,
    share: f64,
    edge: usize,
    along: f64,
}

/// How much the horizontal change per mm of depth of each point of a leg's `top` ring (the
/// mesh's own, from the ring `below` it) must change to be the hips' (`slope`, ray by ray,
/// where its [`Pull`] takes it), at most [`MAX_TURN`], times the share of the pull and fading
/// to nothing at the plane x = `axis` over [`BESIDE_PLANE_MM`].
fn slope_change(
    top: &Layer,
    below: &Layer,
    slope: &[DVec2],
    pulls: &[Pull],
    axis: f64,
) -> Vec<DVec2> {
    let depth = top.z - below.z;
    if depth <= 0.0 {
        return vec![DVec2::ZERO; top.points.len()];
    }
    let n = slope.len();
    top.points
        .iter()
        .zip(&below.points)
        .zip(pulls)
        .map(|((p, q), pull)| {
            let hips = slope[pull.edge].lerp(slope[(pull.edge + 1) % n], pull.along);
            let beside = smoothstep((p.x - axis).abs() / BESIDE_PLANE_MM);
            (hips - (*q - *p) / depth).clamp_length_max(MAX_TURN) * pull.share * beside
        })
        .collect()
}

/// Eases one leg's rings (bottom to top) into `surface`, the hips continued down to its top
/// ring (symmetric about the plane x = `axis`), whose horizontal change per mm of depth is
/// `slope` (ray by ray). A ring `t` mm below the top moves by the top's move times
/// `smoothstep(1 - t / EASE_MM)`, and by the change of slope ([`slope_change`]) times
/// `t (1 - t / EASE_MM)^2`: the thigh leaves the hips at their slope and comes back to its own
/// with zero slope [`EASE_MM`] below. With the top's move alone the thigh kept its own slope
/// up to the join: a kink of 6-15 degrees along the back of the legs' top ring on the
/// MakeHuman bodies, a light line across the thighs at the crotch.
fn ease_leg(leg: &mut [Layer], surface: &Contour, slope: &[DVec2], axis: f64) {
    let [.., below, top] = leg else { return };
    let pulls = pull(&top.points, surface, axis);
    if pulls.iter().all(|p| p.share == 0.0) {
        return;
    }
    let turns = slope_change(top, below, slope, &pulls, axis);
    let top_z = top.z;
    for layer in leg.iter_mut() {
        let t = top_z - layer.z;
        if t >= EASE_MM {
            continue;
        }
        let (w, v) = (smoothstep(1.0 - t / EASE_MM), t * (1.0 - t / EASE_MM).powi(2));
        let points =
            layer.points.iter().zip(&pulls).zip(&turns).map(|((p, d), s)| *p + d.to * w + *s * v);
        let ring = Contour { points: points.collect() };
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
    let depth = hips.z - z;
    let slope = hips_slope(hips, above);
    Contour { points: hips.points.iter().zip(&slope).map(|(&p, &s)| p + s * depth).collect() }
}

/// The horizontal change per mm of depth of the hips, ray by ray: from the layer `above` the
/// lowest torso layer `hips` down to it.
fn hips_slope(hips: &Layer, above: &Layer) -> Vec<DVec2> {
    let rise = above.z - hips.z;
    hips.points.iter().zip(&above.points).map(|(&p, &q)| (p - q) / rise).collect()
}

/// Eases both legs' top rings into the two lowest torso layers `hips` and `above` (see the
/// module documentation).
pub(super) fn ease(hips: &Layer, above: &Layer, left: &mut [Layer], right: &mut [Layer]) {
    let slope = hips_slope(hips, above);
    for leg in [left, right] {
        let Some(top_z) = leg.last().map(|top| top.z) else { continue };
        ease_leg(leg, &continued_down(hips, above, top_z), &slope, hips.centre[0]);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::body::regions::Region;
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
                assert!(((*p + d.to).length() - 100.0).abs() < 0.01, "{p} moved by {}", d.to);
            }
        }
        let deep = pull(&ring(80.0), &surface, -1000.0);
        assert!(deep.iter().all(|d| d.to == DVec2::ZERO), "a thigh 20 mm inside moved");
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

    #[test]
    fn the_thigh_leaves_the_hips_at_their_slope_and_comes_back_to_its_own() {
        // Upright hips of radius 100 mm; a thigh of radius 103 mm at its top (z = -1) widening
        // 0.5 mm per mm down, in rings 0.5 mm apart.
        let (hips, above) = (circle(1.0, |_| 100.0), circle(7.0, |_| 100.0));
        let radius = |z: f64| 103.0 + 0.5 * (-1.0 - z);
        let mut leg: Vec<Layer> = (0..160)
            .rev()
            .map(|k| -1.0 - 0.5 * k as f64)
            .map(|z| circle(z, |_| radius(z)))
            .collect();
        ease(&hips, &above, &mut leg, &mut []);
        let r = |k: usize| leg[leg.len() - 1 - k].points[0].length();
        assert!((r(0) - 100.0).abs() < 1e-9, "the top meets the hips: {}", r(0));
        // Its own slope would drop 0.25 mm to the next ring.
        assert!((r(1) - r(0)).abs() < 0.01, "leaves them upright: {} then {}", r(0), r(1));
        for k in 80..160 {
            let own = radius(leg[leg.len() - 1 - k].z);
            assert!(
                (r(k) - own).abs() < 1e-9,
                "{} mm down: {} against {own}",
                0.5 * k as f64,
                r(k)
            );
        }
    }
}
