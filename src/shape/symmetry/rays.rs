//! Casting rays from a section's centre to its contour.
//!
//! A ray may cross a non-star-shaped contour several times (at the armpits, the crotch, a
//! deep gluteal cleft); it takes its **farthest** crossing. That is one rule for every shape:
//! for a star-shaped section it is the only crossing, and elsewhere it gives the outline a tape
//! would follow across the concavity along that ray. A ray that misses the contour (possible
//! only when the centre lies outside it) takes the contour's extent in its direction.

use crate::body::slice::Contour;
use glam::DVec2;
use std::f64::consts::{FRAC_PI_2, PI, TAU};

/// Unit direction of ray `i` of `n` (ray 0 to the front, -Y; counter-clockwise from above).
pub fn direction(i: usize, n: usize) -> DVec2 {
    let a = 1.5 * PI + TAU * i as f64 / n as f64;
    DVec2::new(a.cos(), a.sin())
}

/// Distance from `centre` to the farthest crossing of `contour` along each of `n` rays: the
/// same as [`cast_along`] the directions of [`direction`], found faster. An edge can only be
/// crossed by the rays between its ends' directions, so each edge is tried against those (and
/// one more each side, far beyond any rounding), not against every ray; an edge within
/// [`NEAR_CENTRE_MM`] of the centre or turning more than [`MAX_TURN`] about it is tried
/// against every ray. Each crossing is computed as [`cast_along`] computes it, and the
/// farthest is the same whatever the order, so the radii are the same to the bit.
pub fn cast(contour: &Contour, centre: DVec2, n: usize) -> Vec<f64> {
    let directions: Vec<DVec2> = (0..n).map(|i| direction(i, n)).collect();
    let pts = &contour.points;
    let m = pts.len();
    let mut farthest: Vec<Option<f64>> = vec![None; n];
    // The fractional index of the ray along `angle` (radians, counter-clockwise from +X).
    let ray = |angle: f64| (angle - 1.5 * PI) / TAU * n as f64;
    for k in 0..m {
        let (a, b) = (pts[k] - centre, pts[(k + 1) % m] - centre);
        let mut try_ray = |i: usize| {
            if let Some(t) = crossing(directions[i], a, b) {
                farthest[i] = Some(farthest[i].map_or(t, |f: f64| f.max(t)));
            }
        };
        let turn = a.perp_dot(b).atan2(a.dot(b));
        if a.length() < NEAR_CENTRE_MM || b.length() < NEAR_CENTRE_MM || turn.abs() > MAX_TURN {
            (0..n).for_each(try_ray);
            continue;
        }
        let from = ray(a.y.atan2(a.x));
        let to = from + turn / TAU * n as f64;
        let (first, last) = (from.min(to).floor() as i64 - 1, from.max(to).ceil() as i64 + 1);
        (first..=last).for_each(|i| try_ray(i.rem_euclid(n as i64) as usize));
    }
    farthest
        .into_iter()
        .zip(&directions)
        .map(|(f, &d)| f.unwrap_or_else(|| extent(pts, centre, d)))
        .collect()
}

/// [`cast`] tries an edge this close to the centre (mm) against every ray: its ends'
/// directions mean little there.
const NEAR_CENTRE_MM: f64 = 1e-3;

/// [`cast`] tries an edge turning more than this about the centre (radians) against every
/// ray: a quarter turn, far more than a section's edge turns about its centre (at most a few
/// degrees), far less than the half turn beyond which the ends' directions no longer bound
/// the crossing rays.
const MAX_TURN: f64 = FRAC_PI_2;

/// Distance from `centre` to the farthest crossing of `contour` along each unit direction.
pub fn cast_along(contour: &Contour, centre: DVec2, directions: &[DVec2]) -> Vec<f64> {
    let pts = &contour.points;
    let m = pts.len();
    directions
        .iter()
        .map(|&d| {
            let mut farthest: Option<f64> = None;
            for k in 0..m {
                if let Some(t) = crossing(d, pts[k] - centre, pts[(k + 1) % m] - centre) {
                    farthest = Some(farthest.map_or(t, |f: f64| f.max(t)));
                }
            }
            farthest.unwrap_or_else(|| extent(pts, centre, d))
        })
        .collect()
}

/// How far along the unit direction `d` from `centre` the ray crosses the edge from `a` to
/// `b` (both relative to `centre`), if it does.
fn crossing(d: DVec2, a: DVec2, b: DVec2) -> Option<f64> {
    let e = b - a;
    let denom = d.perp_dot(e);
    if denom.abs() < 1e-300 {
        return None;
    }
    // centre + t d = a + s e  =>  t = a x e / (d x e), s = a x d / (d x e)
    let t = a.perp_dot(e) / denom;
    let s = a.perp_dot(d) / denom;
    (t >= 0.0 && (0.0..=1.0).contains(&s)).then_some(t)
}

/// What a ray along `d` that misses the contour `pts` takes: the contour's extent in its
/// direction from `centre`.
fn extent(pts: &[DVec2], centre: DVec2, d: DVec2) -> f64 {
    pts.iter().map(|p| (*p - centre).dot(d)).fold(0.0, f64::max)
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
    fn cast_gives_the_radii_of_cast_along_to_the_bit() {
        // A wavy, non-star-shaped loop (a flower with deep petals), from centres inside, on an
        // edge, on a vertex and outside, with few and many rays.
        let flower = Contour {
            points: (0..997)
                .map(|k| {
                    let a = TAU * k as f64 / 997.0;
                    let r = 300.0 + 180.0 * (7.0 * a).sin() + 3.0 * (91.0 * a).cos();
                    DVec2::new(r * a.cos() + 0.3 * (5.0 * a).sin() * r, r * a.sin())
                })
                .collect(),
        };
        let on_edge = (flower.points[10] + flower.points[11]) / 2.0;
        for centre in
            [DVec2::ZERO, DVec2::new(40.0, -25.0), on_edge, flower.points[3], DVec2::X * 900.0]
        {
            for n in [4, 7, 72, 360, 1000] {
                let directions: Vec<DVec2> = (0..n).map(|i| direction(i, n)).collect();
                let (fast, all) =
                    (cast(&flower, centre, n), cast_along(&flower, centre, &directions));
                let bits = |r: &[f64]| r.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
                assert_eq!(bits(&fast), bits(&all), "centre {centre}, {n} rays");
            }
        }
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
