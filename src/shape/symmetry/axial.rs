//! Axial symmetry of a torso section (paper eq. 5-8).

use super::{Preserve, SymmetryError, rays, rescale};
use crate::body::slice::Contour;
use glam::DVec2;

/// A torso section made symmetric about the vertical plane x = `axis`.
#[derive(Debug, Clone, PartialEq)]
pub struct AxialRing {
    /// The ray origin after the move onto the symmetry plane: (`axis`, bounding-box centre y).
    pub centre: DVec2,
    /// `n - 2` points, counter-clockwise from above, starting just left (+X) of the front
    /// midline; the two rays on the symmetry line (0 and n/2) are dropped (paper, eq. 7).
    pub points: Vec<DVec2>,
}

/// Makes `section` symmetric with `n` rays:
/// - eq. 5: the centre is the section's bounding-box centre (moved inside the section along
///   the vertical line through it where it lies outside, [`rays::ray_origin`]); the section is moved sideways so
///   that the centre lies on the body's symmetry plane x = `axis` (one plane for the whole
///   mannequin, so that it is mirror-symmetric as a whole);
/// - eq. 6: ray `i` meets the contour at distance `r_i` (farthest crossing);
/// - eq. 7: each ray and its mirror image take the mean `(r_i + r_(n-i)) / 2`;
/// - eq. 8: the result is scaled about the centre to the section's original girth.
///
/// ```
/// use dressform::body::slice::Contour;
/// use dressform::shape::symmetry::{Preserve, axial};
/// use glam::DVec2;
///
/// // A lopsided section: a 200 x 100 mm box with its left side pushed 40 mm out at the front.
/// let points = [(-100., -50.), (140., -50.), (100., 50.), (-100., 50.)]
///     .map(|(x, y)| DVec2::new(x, y))
///     .to_vec();
/// let section = Contour { points };
/// let ring = axial::symmetrize(&section, 0.0, 360, Preserve::Tape).unwrap();
///
/// assert_eq!(ring.points.len(), 358); // the two rays on the symmetry line are dropped
/// let n = ring.points.len();
/// for (k, p) in ring.points.iter().enumerate() {
///     let partner = ring.points[n - 1 - k]; // its mirror image about x = 0
///     assert!((p.x + partner.x).abs() < 1e-9 && (p.y - partner.y).abs() < 1e-9);
/// }
/// let symmetric = Contour { points: ring.points };
/// assert!((symmetric.tape_girth() - section.tape_girth()).abs() < 1e-9); // eq. 8
/// ```
pub fn symmetrize(
    section: &Contour,
    axis: f64,
    n: usize,
    preserve: Preserve,
) -> Result<AxialRing, SymmetryError> {
    super::check_rays(n)?;
    if section.points.len() < 3 {
        return Err(SymmetryError::EmptySection(f64::NAN));
    }
    let c = rays::ray_origin(section);
    let r = rays::cast(section, c, n);
    Ok(mirror_mean(&r, &r, c.y, axis, preserve, preserve.girth(section)))
}

/// [`symmetrize`] for a section whose two halves come from two sections: the left half (+X,
/// rays 1 to `n/2 - 1`) from `left`, the right half from `right`, scaled to the girth `girth`
/// (eq. 8). The centre (eq. 5) is the bounding-box centre of the two halves put together:
/// `left` from the middle of the two sections' outer extents outwards, `right` inwards of
/// it. Each section's rays start there, each moved inside its own section as
/// [`rays::ray_origin`] moves them. Given one section twice and its own girth, the ring
/// [`symmetrize`] makes.
pub fn symmetrize_halves(
    left: &Contour,
    right: &Contour,
    axis: f64,
    n: usize,
    preserve: Preserve,
    girth: f64,
) -> Result<AxialRing, SymmetryError> {
    super::check_rays(n)?;
    if left.points.len() < 3 || right.points.len() < 3 {
        return Err(SymmetryError::EmptySection(f64::NAN));
    }
    let c = halves_centre(left, right);
    let (cl, cr) = (rays::ray_origin_at(left, c), rays::ray_origin_at(right, c));
    let (rl, rr) = (rays::cast(left, cl, n), rays::cast(right, cr, n));
    Ok(mirror_mean(&rl, &rr, 0.5 * (cl.y + cr.y), axis, preserve, girth))
}

/// The bounding-box centre of the left half of `left` and the right half of `right`, the
/// halves split at the middle of `left`'s largest x and `right`'s smallest (eq. 5).
fn halves_centre(left: &Contour, right: &Contour) -> DVec2 {
    let extreme = |c: &Contour, pick: fn(f64, f64) -> f64, from: f64| {
        c.points.iter().map(|p| p.x).fold(from, pick)
    };
    let x = 0.5
        * (extreme(left, f64::max, f64::NEG_INFINITY) + extreme(right, f64::min, f64::INFINITY));
    let halves = [left.clip_x(x, f64::INFINITY), right.clip_x(f64::NEG_INFINITY, x)];
    let ys = halves.iter().flat_map(|h| h.points.iter().map(|p| p.y));
    let (lo, hi) =
        ys.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), y| (lo.min(y), hi.max(y)));
    DVec2::new(x, 0.5 * (lo + hi))
}

/// Eq. 7 and 8: the ring about the centre (`axis`, `centre_y`) whose ray `i` and its mirror
/// image `n - i` both take the mean of the two rays' distances, each ray's from its own side
/// (`left` for the rays to +X, 1 to `n/2 - 1`; `right` for the others), scaled to `girth`.
fn mirror_mean(
    left: &[f64],
    right: &[f64],
    centre_y: f64,
    axis: f64,
    preserve: Preserve,
    girth: f64,
) -> AxialRing {
    let n = left.len();
    let r = |i: usize| if i < n / 2 { left[i] } else { right[i] };
    let centre = DVec2::new(axis, centre_y);
    let mut points: Vec<DVec2> = (1..n)
        .filter(|&i| i != n / 2)
        .map(|i| centre + rays::direction(i, n) * (0.5 * (r(i) + r(n - i))))
        .collect();
    rescale(&mut points, centre, preserve, girth);
    AxialRing { centre, points }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::TAU;

    fn ellipse(a: f64, b: f64, centre: DVec2, m: usize) -> Contour {
        Contour {
            points: (0..m)
                .map(|k| {
                    let t = TAU * k as f64 / m as f64;
                    centre + DVec2::new(a * t.cos(), b * t.sin())
                })
                .collect(),
        }
    }

    fn assert_mirror_symmetric(ring: &AxialRing, axis: f64) {
        let n = ring.points.len();
        for (j, p) in ring.points.iter().enumerate() {
            let partner = ring.points[n - 1 - j];
            assert!((p.x - axis + partner.x - axis).abs() < 1e-9 && (p.y - partner.y).abs() < 1e-9);
        }
    }

    #[test]
    fn an_off_centre_asymmetric_section_becomes_symmetric_with_its_girth() {
        // An egg: wider on the left, moved off the axis.
        let mut egg = ellipse(150.0, 110.0, DVec2::new(23.0, -4.0), 720);
        for p in &mut egg.points {
            p.x += 0.0004 * (p.x - 23.0).max(0.0).powi(2);
        }
        for preserve in [Preserve::Tape, Preserve::Contour] {
            let ring = symmetrize(&egg, 0.0, 360, preserve).unwrap();
            assert_eq!(ring.points.len(), 358);
            assert_mirror_symmetric(&ring, 0.0);
            let out = Contour { points: ring.points.clone() };
            assert!((preserve.girth(&out) - preserve.girth(&egg)).abs() < 1e-6);
            assert!(out.signed_area() > 0.0);
        }
    }

    #[test]
    fn a_symmetric_section_is_unchanged() {
        let e = ellipse(160.0, 120.0, DVec2::new(0.0, 30.0), 2000);
        let ring = symmetrize(&e, 0.0, 360, Preserve::Tape).unwrap();
        for p in &ring.points {
            let q = (*p - DVec2::new(0.0, 30.0)) / DVec2::new(160.0, 120.0);
            assert!((q.length() - 1.0).abs() < 1e-4, "{p} is off the ellipse");
        }
    }

    #[test]
    fn a_non_star_shaped_section_gives_a_simple_symmetric_ring() {
        // A kidney: a disc with a deep bite from the back, as at a gluteal cleft or the crotch.
        let kidney = Contour {
            points: (0..720)
                .map(|k| {
                    let t = TAU * k as f64 / 720.0;
                    let bite = 70.0 * (-(((t - TAU / 4.0) / 0.35).powi(2))).exp();
                    DVec2::new(t.cos(), t.sin()) * (120.0 - bite)
                })
                .collect(),
        };
        let ring = symmetrize(&kidney, 0.0, 360, Preserve::Tape).unwrap();
        assert_mirror_symmetric(&ring, 0.0);
        let out = Contour { points: ring.points };
        assert!((out.tape_girth() - kidney.tape_girth()).abs() < 1e-6);
        assert!(out.signed_area() > 0.0, "still counter-clockwise");
    }

    #[test]
    fn one_section_given_twice_is_made_symmetric_as_it_is_alone() {
        let mut egg = ellipse(150.0, 110.0, DVec2::new(23.0, -4.0), 720);
        for p in &mut egg.points {
            p.x += 0.0004 * (p.x - 23.0).max(0.0).powi(2);
        }
        let girth = Preserve::Tape.girth(&egg);
        let halves = symmetrize_halves(&egg, &egg, 0.0, 360, Preserve::Tape, girth).unwrap();
        assert_eq!(halves, symmetrize(&egg, 0.0, 360, Preserve::Tape).unwrap());
    }

    #[test]
    fn each_half_comes_from_its_own_section() {
        // The left half (+X) from a 200 mm wide ellipse, the right from a 240 mm wide one: the
        // ring of the section they make together, split at the middle of their outer ends.
        let (a_left, a_right, b) = (100.0, 120.0, 80.0);
        let split: f64 = 0.5 * (a_left - a_right);
        let arc = |a: f64, from: f64, to: f64| {
            (0..=2000).map(move |k| {
                let t = from + (to - from) * k as f64 / 2000.0;
                DVec2::new(a * t.cos(), b * t.sin())
            })
        };
        let (t_left, t_right) = ((split / a_left).acos(), (split / a_right).acos());
        let together = Contour {
            points: arc(a_left, -t_left, t_left)
                .chain(arc(a_right, t_right, TAU - t_right))
                .collect(),
        };
        let (left, right) =
            (ellipse(a_left, b, DVec2::ZERO, 4000), ellipse(a_right, b, DVec2::ZERO, 4000));
        let girth = Preserve::Tape.girth(&together);
        let ring = symmetrize_halves(&left, &right, 0.0, 360, Preserve::Tape, girth).unwrap();
        let whole = symmetrize(&together, 0.0, 360, Preserve::Tape).unwrap();
        assert!((ring.centre - whole.centre).length() < 1e-6, "{} {}", ring.centre, whole.centre);
        for (p, q) in ring.points.iter().zip(&whole.points) {
            assert!(p.distance(*q) < 0.05, "{p} against {q}");
        }
    }

    #[test]
    fn odd_ray_counts_are_refused() {
        let e = ellipse(1.0, 1.0, DVec2::ZERO, 10);
        assert_eq!(symmetrize(&e, 0.0, 359, Preserve::Tape), Err(SymmetryError::BadRayCount(359)));
    }
}
