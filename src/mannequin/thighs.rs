//! The thighs' top layers eased into the hips above them.
//!
//! The lowest torso layer (just above the crotch) and the legs' top layers (just below it)
//! are made symmetric each on its own rays: the torso's from the torso's centre, the legs'
//! from each leg's. Where a torso section is not star-shaped from its centre — the gluteal
//! cleft, the groove beside the pubis — its farthest crossing cuts across the hollow, and the
//! torso ring runs up to 10 mm inside the thigh ring 2 mm below it: a step that the band
//! between them can only bridge lying flat (a crease of over 100 degrees, a line across the
//! thighs in a shaded picture). A thigh never sticks out of the hip above it on a body, so
//! where the top leg ring does, it is pulled in onto the lowest torso ring, and the layers
//! below follow a smooth fraction of that pull over [`EASE_MM`] of height. Each eased layer
//! reports the girth of its new shape; the torso is not changed.

use super::Layer;
use super::rebuild::closest_on_ring;
use crate::slice::Contour;
use glam::DVec2;

/// The height over which the pull fades out below the crotch (mm): two to three leg layers
/// at the paper's 50 leg layers, so a 10 mm pull slopes at most about 1 in 4.
const EASE_MM: f64 = 40.0;

/// The smooth step from 0 (at `t` <= 0) to 1 (at `t` >= 1), with zero slope at both ends.
fn smoothstep(t: f64) -> f64 {
    let t = t.clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

/// How far each point of the top leg ring `top` must move to lie within the torso ring
/// `hips` above it: to its closest point on `hips` where it lies outside, nothing elsewhere.
fn pull(top: &[DVec2], hips: &Contour) -> Vec<DVec2> {
    top.iter()
        .map(
            |&p| {
                if hips.contains(p) { DVec2::ZERO } else { closest_on_ring(&hips.points, p).2 - p }
            },
        )
        .collect()
}

/// Eases one leg's layers (bottom to top) into the lowest torso layer `hips`.
fn ease_leg(leg: &mut [Layer], hips: &Contour) {
    let Some(top) = leg.last() else { return };
    let (top_z, moves) = (top.z, pull(&top.points, hips));
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

/// Eases both legs' top layers into the lowest torso layer `hips` (see the module
/// documentation).
pub(super) fn ease(hips: &Layer, left: &mut [Layer], right: &mut [Layer]) {
    let hips = Contour { points: hips.points.clone() };
    ease_leg(left, &hips);
    ease_leg(right, &hips);
}
