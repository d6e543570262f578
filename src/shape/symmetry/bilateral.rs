//! Bilateral symmetry of the two legs (paper eq. 9-12).

use super::{Preserve, SymmetryError, rays, rescale};
use crate::body::slice::Contour;
use glam::DVec2;

/// A leg section after bilateral symmetry.
#[derive(Debug, Clone, PartialEq)]
pub struct LegRing {
    /// The ray origin.
    pub centre: DVec2,
    /// `n` points, counter-clockwise from above, starting with the ray to the front.
    pub points: Vec<DVec2>,
}

/// Makes the left and right leg sections at one height mirror images of each other about the
/// plane x = `axis`, with `n` rays:
/// - eq. 9: each leg's centre is its bounding-box centre; the new centres are mirror images
///   (mean distance from the plane, mean depth). Over all heights this is the **stance rule**:
///   each leg's centre line is its direction, and the mannequin's legs take the mean of the
///   left leg's direction and the right leg's mirrored (a leg abducted 15 degrees and one at
///   6 degrees give two legs at 10.5 degrees), each leg's shape carried along with its centre;
/// - eq. 10: each leg casts `n` rays (farthest crossing);
/// - eq. 11: left ray `i` and right ray `n - i` (mirror images) take their mean;
/// - eq. 12: both are scaled about their centres to the mean of the two original girths (the
///   legs cannot keep different girths and be mirror images; the sum of their girths is kept).
pub fn symmetrize(
    left: &Contour,
    right: &Contour,
    axis: f64,
    n: usize,
    preserve: Preserve,
) -> Result<[LegRing; 2], SymmetryError> {
    super::check_rays(n)?;
    if left.points.len() < 3 || right.points.len() < 3 {
        return Err(SymmetryError::EmptySection(f64::NAN));
    }
    let (cl, cr) = (left.bbox_centre(), right.bbox_centre());
    let (rl, rr) = (rays::cast(left, cl, n), rays::cast(right, cr, n));
    let offset = 0.5 * ((cl.x - axis) + (axis - cr.x));
    let depth = 0.5 * (cl.y + cr.y);
    let centre_left = DVec2::new(axis + offset, depth);
    let centre_right = DVec2::new(axis - offset, depth);
    let mean = |i: usize| 0.5 * (rl[i] + rr[(n - i) % n]);
    let mut pl: Vec<DVec2> =
        (0..n).map(|i| centre_left + rays::direction(i, n) * mean(i)).collect();
    let mut pr: Vec<DVec2> =
        (0..n).map(|i| centre_right + rays::direction(i, n) * mean((n - i) % n)).collect();
    let target = 0.5 * (preserve.girth(left) + preserve.girth(right));
    rescale(&mut pl, centre_left, preserve, target);
    rescale(&mut pr, centre_right, preserve, target);
    Ok([LegRing { centre: centre_left, points: pl }, LegRing { centre: centre_right, points: pr }])
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::TAU;

    fn ellipse(a: f64, b: f64, centre: DVec2) -> Contour {
        Contour {
            points: (0..500)
                .map(|k| {
                    let t = TAU * k as f64 / 500.0;
                    centre + DVec2::new(a * t.cos(), b * t.sin())
                })
                .collect(),
        }
    }

    #[test]
    fn two_different_legs_become_mirror_images_with_the_mean_girth() {
        let left = ellipse(80.0, 70.0, DVec2::new(110.0, 12.0));
        let right = ellipse(72.0, 75.0, DVec2::new(-95.0, 4.0));
        let [l, r] = symmetrize(&left, &right, 0.0, 360, Preserve::Tape).unwrap();
        assert!((l.centre.x + r.centre.x).abs() < 1e-12 && l.centre.y == r.centre.y);
        for i in 0..360 {
            let (p, q) = (l.points[i], r.points[(360 - i) % 360]);
            assert!((p.x + q.x).abs() < 1e-9 && (p.y - q.y).abs() < 1e-9, "ray {i}");
        }
        let target = 0.5 * (left.tape_girth() + right.tape_girth());
        for ring in [&l, &r] {
            let g = Contour { points: ring.points.clone() }.tape_girth();
            assert!((g - target).abs() < 1e-6);
        }
    }
}
