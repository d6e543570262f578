//! Casting rays from a section's centre to its contour.
//!
//! A ray may cross a non-star-shaped contour several times (at the armpits, the crotch, a
//! deep gluteal cleft); it takes its **farthest** crossing. That is one rule for every shape:
//! for a star-shaped section it is the only crossing, and elsewhere it gives the outline a tape
//! would follow across the concavity along that ray. A ray that misses the contour (possible
//! only when the centre lies outside it) takes the contour's extent in its direction.

use crate::body::slice::Contour;
use glam::DVec2;
use std::f64::consts::{PI, TAU};

/// Unit direction of ray `i` of `n` (ray 0 to the front, -Y; counter-clockwise from above).
pub fn direction(i: usize, n: usize) -> DVec2 {
    let a = 1.5 * PI + TAU * i as f64 / n as f64;
    DVec2::new(a.cos(), a.sin())
}

/// Distance from `centre` to the farthest crossing of `contour` along each of `n` rays.
pub fn cast(contour: &Contour, centre: DVec2, n: usize) -> Vec<f64> {
    let directions: Vec<DVec2> = (0..n).map(|i| direction(i, n)).collect();
    cast_along(contour, centre, &directions)
}

/// Distance from `centre` to the farthest crossing of `contour` along each unit direction.
pub fn cast_along(contour: &Contour, centre: DVec2, directions: &[DVec2]) -> Vec<f64> {
    let pts = &contour.points;
    let m = pts.len();
    directions
        .iter()
        .map(|&d| {
            let mut farthest: Option<f64> = None;
            for k in 0..m {
                let (a, b) = (pts[k] - centre, pts[(k + 1) % m] - centre);
                let e = b - a;
                let denom = d.perp_dot(e);
                if denom.abs() < 1e-300 {
                    continue;
                }
                // centre + t d = a + s e  =>  t = a x e / (d x e), s = a x d / (d x e)
                let t = a.perp_dot(e) / denom;
                let s = a.perp_dot(d) / denom;
                if t >= 0.0 && (0.0..=1.0).contains(&s) {
                    farthest = Some(farthest.map_or(t, |f: f64| f.max(t)));
                }
            }
            farthest.unwrap_or_else(|| pts.iter().map(|p| (*p - centre).dot(d)).fold(0.0, f64::max))
        })
        .collect()
}

/// The rays' origin for `contour`: its bounding-box centre (eq. 5), or, where that lies
/// outside the contour, the middle of the longest stretch of the vertical line through it
/// (x unchanged, so the section still moves onto the symmetry plane by its bounding box) that
/// lies inside. A loop just formed above the crotch wraps around the gluteal cleft, which
/// holds its bounding-box centre: from there the rays towards the back miss the loop, and each
/// would take the loop's extent, a flap behind the buttocks.
pub fn ray_origin(contour: &Contour) -> DVec2 {
    ray_origin_at(contour, contour.bbox_centre())
}

/// `c`, or, where it lies outside `contour`, the middle of the longest stretch of the vertical
/// line through it that lies inside (`c` itself where that line misses the contour): the
/// rays' origin of [`ray_origin`] for any centre `c`.
pub fn ray_origin_at(contour: &Contour, c: DVec2) -> DVec2 {
    if contour.contains(c) {
        return c;
    }
    let pts = &contour.points;
    let mut ys: Vec<f64> = (0..pts.len())
        .filter_map(|k| {
            let (a, b) = (pts[k], pts[(k + 1) % pts.len()]);
            ((a.x > c.x) != (b.x > c.x)).then(|| a.y + (b.y - a.y) * (c.x - a.x) / (b.x - a.x))
        })
        .collect();
    ys.sort_by(f64::total_cmp);
    let longest = ys.chunks_exact(2).max_by(|p, q| (p[1] - p[0]).total_cmp(&(q[1] - q[0])));
    longest.map_or(c, |p| DVec2::new(c.x, 0.5 * (p[0] + p[1])))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rays_start_inside_a_loop_that_wraps_around_its_bounding_box_centre() {
        // A "U" open to the back (+Y), as just above the crotch: the bbox centre (0, 0) lies
        // in the notch; the origin moves onto the line x = 0 inside the base of the U.
        let u = Contour {
            points: [
                (-3., -3.),
                (3., -3.),
                (3., 3.),
                (1., 3.),
                (1., -1.),
                (-1., -1.),
                (-1., 3.),
                (-3., 3.),
            ]
            .iter()
            .map(|&(x, y)| DVec2::new(x, y))
            .collect(),
        };
        assert_eq!(ray_origin(&u), DVec2::new(0.0, -2.0));
        // Every ray from the origin ends on the U; from the bbox centre some miss it.
        let off_the_u = |origin: DVec2| {
            let r = cast(&u, origin, 360);
            (0..360)
                .filter(|&i| {
                    let p = origin + direction(i, 360) * r[i];
                    let n = u.points.len();
                    (0..n).all(|k| {
                        let (a, b) = (u.points[k], u.points[(k + 1) % n]);
                        let t = ((p - a).dot(b - a) / (b - a).length_squared()).clamp(0.0, 1.0);
                        p.distance(a + (b - a) * t) > 1e-9
                    })
                })
                .count()
        };
        assert_eq!(off_the_u(ray_origin(&u)), 0);
        assert!(off_the_u(u.bbox_centre()) > 0);
    }

    #[test]
    fn directions_start_at_the_front_and_mirror_pairwise() {
        let n = 360;
        assert!((direction(0, n) - DVec2::NEG_Y).length() < 1e-12);
        assert!((direction(n / 2, n) - DVec2::Y).length() < 1e-12);
        assert!(
            direction(1, n).x > 0.0,
            "counter-clockwise from the front goes to the subject's left (+X)"
        );
        for i in 1..n {
            let (a, b) = (direction(i, n), direction(n - i, n));
            assert!((a.x + b.x).abs() < 1e-12 && (a.y - b.y).abs() < 1e-12);
        }
    }

    #[test]
    fn square_radii() {
        let sq = Contour {
            points: vec![
                DVec2::new(-1., -1.),
                DVec2::new(1., -1.),
                DVec2::new(1., 1.),
                DVec2::new(-1., 1.),
            ],
        };
        let r = cast(&sq, DVec2::ZERO, 8);
        for (i, r) in r.iter().enumerate() {
            let expected = if i % 2 == 0 { 1.0 } else { 2f64.sqrt() };
            assert!((r - expected).abs() < 1e-12, "ray {i}: {r}");
        }
    }

    #[test]
    fn a_ray_crossing_twice_takes_the_farthest_crossing() {
        // A "C" opening to +X: the ray to +X from the centre crosses the two arms' tips.
        let c = Contour {
            points: [
                (-2., -2.),
                (2., -2.),
                (2., -1.),
                (-1., -1.),
                (-1., 1.),
                (2., 1.),
                (2., 2.),
                (-2., 2.),
            ]
            .iter()
            .map(|&(x, y)| DVec2::new(x, y))
            .collect(),
        };
        let r = cast(&c, DVec2::ZERO, 4); // rays: -Y, +X, +Y, -X
        assert!((r[0] - 2.0).abs() < 1e-12);
        assert!((r[3] - 2.0).abs() < 1e-12, "-X hits the back of the C");
        assert!(r[1] >= 0.0, "+X goes through the opening: the contour's extent, {}", r[1]);
    }
}
