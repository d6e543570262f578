//! Calibration on the implicit surface: tape girths of horizontal sections (rays from the
//! torso centre, bisection of the boundary, convex hull perimeter), the crotch height, and the
//! iteration that scales the torso until both match the request.

use glam::DVec3;
use rayon::prelude::*;

use super::anatomy::Anatomy;
use super::body::{Calibration, ImplicitBody};
use super::params::ParamError;

/// Rays per section.
const RAYS: usize = 720;
/// Ray marching step (mm): smaller than any gap the torso loop has to be told apart by.
const RAY_STEP: f64 = 2.0;
/// Farthest a torso boundary can be from its centre (mm).
const RAY_REACH: f64 = 900.0;
/// Relative girth error and crotch error (mm) at which calibration stops.
const GIRTH_TOLERANCE: f64 = 2e-5;
const CROTCH_TOLERANCE: f64 = 0.02;
const MAX_ITERATIONS: usize = 30;

/// The torso loop of a horizontal section of the implicit surface.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct SectionMeasure {
    /// Perimeter of the convex hull (what a tape measures).
    pub tape: f64,
    /// Perimeter of the loop itself (following concavities).
    pub contour: f64,
}

/// Bisects `f` on [`lo`, `hi`] where `f(lo) < 0 <= f(hi)`; returns the boundary parameter.
fn bisect(f: impl Fn(f64) -> f64, mut lo: f64, mut hi: f64) -> f64 {
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if f(mid) < 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
        if hi - lo < 1e-7 {
            break;
        }
    }
    0.5 * (lo + hi)
}

/// Boundary points of the torso loop at height `z`, arms left out (a tape passes between an
/// arm and the torso, even where the arm rests on it): along each of [`RAYS`] rays from the
/// torso centre, the first point where the surface is left. `None` if the centre is outside or a ray
/// never leaves.
pub(crate) fn torso_loop(body: &ImplicitBody, z: f64) -> Option<Vec<[f64; 2]>> {
    loop_around(body, body.torso_centre(z), z)
}

/// Boundary points of the loop at height `z` around the point (`cx`, `cy`), arms left out:
/// along each of [`RAYS`] rays from it, the first point where the surface is left. `None` if
/// the point is outside or a ray never leaves.
pub(crate) fn loop_around(
    body: &ImplicitBody,
    (cx, cy): (f64, f64),
    z: f64,
) -> Option<Vec<[f64; 2]>> {
    let field = |p: DVec3| body.value_without_arms(p);
    let offsets = loop_in_plane(&field, DVec3::new(cx, cy, z), DVec3::X, DVec3::Y)?;
    Some(offsets.into_iter().map(|[u, v]| [cx + u, cy + v]).collect())
}

/// Boundary points of the loop of `field`'s surface in the plane through `centre` spanned by
/// the orthonormal `u` and `v`, as (u, v) offsets from `centre`: along each of [`RAYS`] rays,
/// the first point where the surface is left. `None` if `centre` is outside or a ray never
/// leaves.
pub(crate) fn loop_in_plane(
    field: &(dyn Fn(DVec3) -> f64 + Sync),
    centre: DVec3,
    u: DVec3,
    v: DVec3,
) -> Option<Vec<[f64; 2]>> {
    if field(centre) >= 0.0 {
        return None;
    }
    (0..RAYS)
        .into_par_iter()
        .map(|i| {
            let angle = i as f64 / RAYS as f64 * std::f64::consts::TAU;
            let (s, c) = angle.sin_cos();
            let at = |r: f64| field(centre + (u * c + v * s) * r);
            let mut r = 0.0;
            let mut value = at(r);
            while r < RAY_REACH {
                // The field changes at most about 1 mm per mm: half its magnitude is a safe
                // step towards the first exit.
                let next = r + (0.5 * -value).max(RAY_STEP);
                let next_value = at(next);
                if next_value >= 0.0 {
                    let rb = bisect(at, r, next);
                    return Some([rb * c, rb * s]);
                }
                (r, value) = (next, next_value);
            }
            None
        })
        .collect()
}

/// The tape girth of the body's section (arms included) by the plane through `centre`
/// perpendicular to `axis`, around `centre`: a limb's girth across its axis.
pub(crate) fn tape_girth_across(body: &ImplicitBody, centre: DVec3, axis: DVec3) -> Option<f64> {
    let axis = axis.normalize();
    let u = axis.any_orthonormal_vector();
    let field = |p: DVec3| body.value(p);
    loop_in_plane(&field, centre, u, axis.cross(u)).map(|pts| perimeter(&convex_hull(&pts)))
}

/// The section of the whole surface (arms included) by the plane through `centre`
/// perpendicular to `axis`, as points in space: [`loop_in_plane`]'s. `None` if `centre` is not
/// inside.
pub(crate) fn section_across(
    body: &ImplicitBody,
    centre: DVec3,
    axis: DVec3,
) -> Option<Vec<DVec3>> {
    let axis = axis.normalize();
    let u = axis.any_orthonormal_vector();
    let v = axis.cross(u);
    let field = |p: DVec3| body.value(p);
    let offsets = loop_in_plane(&field, centre, u, v)?;
    Some(offsets.into_iter().map(|[a, b]| centre + u * a + v * b).collect())
}

/// Perimeter of the closed polygon `pts`.
fn perimeter(pts: &[[f64; 2]]) -> f64 {
    (0..pts.len())
        .map(|i| {
            let (a, b) = (pts[i], pts[(i + 1) % pts.len()]);
            (a[0] - b[0]).hypot(a[1] - b[1])
        })
        .sum()
}

/// Convex hull (counter-clockwise, Andrew's monotone chain).
fn convex_hull(pts: &[[f64; 2]]) -> Vec<[f64; 2]> {
    let mut p = pts.to_vec();
    p.sort_by(|a, b| a[0].total_cmp(&b[0]).then(a[1].total_cmp(&b[1])));
    p.dedup();
    if p.len() < 3 {
        return p;
    }
    let cross = |o: [f64; 2], a: [f64; 2], b: [f64; 2]| {
        (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])
    };
    let mut hull: Vec<[f64; 2]> = Vec::with_capacity(2 * p.len());
    for pass in 0..2 {
        let start = hull.len();
        let iter: Box<dyn Iterator<Item = &[f64; 2]>> =
            if pass == 0 { Box::new(p.iter()) } else { Box::new(p.iter().rev()) };
        for &q in iter {
            while hull.len() >= start + 2
                && cross(hull[hull.len() - 2], hull[hull.len() - 1], q) <= 0.0
            {
                hull.pop();
            }
            hull.push(q);
        }
        hull.pop();
    }
    hull
}

/// Tape girth of the loop at height `z` around (`cx`, `cy`), arms left out.
pub(crate) fn tape_girth_around(body: &ImplicitBody, centre: (f64, f64), z: f64) -> Option<f64> {
    loop_around(body, centre, z).map(|pts| perimeter(&convex_hull(&pts)))
}

/// Tape and contour girth of the torso loop at height `z`.
pub(crate) fn measure_section(body: &ImplicitBody, z: f64) -> Option<SectionMeasure> {
    let pts = torso_loop(body, z)?;
    Some(SectionMeasure { tape: perimeter(&convex_hull(&pts)), contour: perimeter(&pts) })
}

/// Height of the lowest surface point above the floor on the vertical line through (`x`, `y`)
/// below `z_inside` (which must be inside).
fn surface_below(body: &ImplicitBody, x: f64, y: f64, z_inside: f64) -> Option<f64> {
    let at = |z: f64| body.value(DVec3::new(x, y, z));
    if at(z_inside) >= 0.0 {
        return None;
    }
    let mut z = z_inside;
    while z > 0.0 {
        let next = z - RAY_STEP;
        if at(next) >= 0.0 {
            // `at` is negative at the top: bisect on depth below z_inside.
            let d = bisect(|d| at(z_inside - d), z_inside - z, z_inside - next);
            return Some(z_inside - d);
        }
        z = next;
    }
    None
}

/// The crotch: on the mid-sagittal plane, the lowest point of the torso between the legs
/// (the saddle point of the surface there). Returns (y, z).
pub(crate) fn crotch_point(body: &ImplicitBody, a: &Anatomy) -> Option<(f64, f64)> {
    let z_inside = a.levels[0];
    let (_, yc) = body.torso_centre(a.crotch_height);
    let low = |y: f64| surface_below(body, 0.0, y, z_inside).unwrap_or(f64::MAX);
    // Coarse scan, then golden-section refinement around the lowest sample.
    let (mut best_y, mut best_z) = (yc, low(yc));
    for i in -40..=40 {
        let y = yc + 2.0 * f64::from(i);
        let z = low(y);
        if z < best_z {
            (best_y, best_z) = (y, z);
        }
    }
    if best_z == f64::MAX {
        return None;
    }
    let (mut lo, mut hi) = (best_y - 2.0, best_y + 2.0);
    let g = 0.5 * (5f64.sqrt() - 1.0);
    for _ in 0..30 {
        let (y1, y2) = (hi - g * (hi - lo), lo + g * (hi - lo));
        if low(y1) < low(y2) {
            hi = y2;
        } else {
            lo = y1;
        }
    }
    let y = 0.5 * (lo + hi);
    Some((y, low(y).min(best_z)))
}

/// The calibrated body and its measured levels.
pub(crate) struct Calibrated {
    pub body: ImplicitBody,
    /// Tape/contour girth at the hip, waist and chest levels.
    pub sections: [SectionMeasure; 3],
    /// Crotch point (y, z).
    pub crotch: (f64, f64),
}

/// Scales the torso at the hip, waist and chest levels (secant iteration per level, the
/// levels are independent since the scale is flat at each) and moves the torso's bottom plane
/// until the implicit surface has the requested tape girths and crotch height.
pub(crate) fn calibrate(a: &Anatomy) -> Result<Calibrated, ParamError> {
    let mut cal = Calibration::initial(a);
    let mut previous: [Option<(f64, f64)>; 3] = [None; 3];
    let mut previous_crotch: Option<(f64, f64)> = None;
    let names = ["hip", "waist", "chest"];
    for _ in 0..MAX_ITERATIONS {
        let body = ImplicitBody::new(a, &cal);
        let mut sections = Vec::with_capacity(3);
        for (l, name) in names.iter().enumerate() {
            let m = measure_section(&body, a.levels[l]).ok_or_else(|| {
                ParamError::Calibration(format!(
                    "the {name} section at z = {:.0} mm has no closed torso loop",
                    a.levels[l]
                ))
            })?;
            sections.push(m);
        }
        let crotch = crotch_point(&body, a).ok_or_else(|| {
            ParamError::Calibration("no crotch found between the legs".to_string())
        })?;
        let girth_ok =
            (0..3).all(|l| (sections[l].tape / a.girths[l] - 1.0).abs() < GIRTH_TOLERANCE);
        let crotch_ok = (crotch.1 - a.crotch_height).abs() < CROTCH_TOLERANCE;
        if girth_ok && crotch_ok {
            let sections: [SectionMeasure; 3] =
                [sections[0].clone(), sections[1].clone(), sections[2].clone()];
            return Ok(Calibrated { body, sections, crotch });
        }
        for l in 0..3 {
            let (s, g) = (cal.scale[l], sections[l].tape);
            cal.scale[l] = secant_step(previous[l], (s, g), a.girths[l], |s, g, t| s * t / g);
            previous[l] = Some((s, g));
        }
        let (zb, zc) = (cal.bottom_z, crotch.1);
        // The bottom plane stays near the crotch: far from it, the crotch is not the torso's.
        let reach = 0.05 * a.height;
        cal.bottom_z = secant_step(previous_crotch, (zb, zc), a.crotch_height, |b, c, t| b + t - c)
            .clamp(a.crotch_height - reach, a.crotch_height + reach);
        previous_crotch = Some((zb, zc));
    }
    Err(ParamError::Calibration(format!(
        "girths or crotch height did not converge in {MAX_ITERATIONS} iterations"
    )))
}

/// One secant step towards `target` for a monotone response: from the current (input, output)
/// and the previous pair; falls back to `simple` when the secant is unusable, and never moves
/// more than the simple step would by a factor of three.
fn secant_step(
    previous: Option<(f64, f64)>,
    (x, y): (f64, f64),
    target: f64,
    simple: impl Fn(f64, f64, f64) -> f64,
) -> f64 {
    let fallback = simple(x, y, target);
    let Some((px, py)) = previous else {
        return fallback;
    };
    let slope = (y - py) / (x - px);
    if !slope.is_finite() || slope <= 0.0 {
        return fallback;
    }
    let step = (target - y) / slope;
    let limit = 3.0 * (fallback - x).abs() + 1e-9;
    x + step.clamp(-limit, limit)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hull_of_a_square_with_inner_points() {
        let pts = [[0.0, 0.0], [2.0, 0.0], [1.0, 0.5], [2.0, 2.0], [0.0, 2.0], [1.0, 1.0]];
        let h = convex_hull(&pts);
        assert_eq!(h.len(), 4);
        assert!((perimeter(&h) - 8.0).abs() < 1e-12);
    }

    #[test]
    fn secant_converges_on_a_line() {
        let f = |x: f64| 3.0 * x + 1.0;
        let mut prev = None;
        let mut x = 1.0;
        for _ in 0..4 {
            let y = f(x);
            let nx = secant_step(prev, (x, y), 10.0, |x, y, t| x * t / y);
            prev = Some((x, y));
            x = nx;
        }
        assert!((f(x) - 10.0).abs() < 1e-9);
    }
}

#[cfg(test)]
mod calibrated_body_tests {
    use super::*;
    use crate::params::{BodyParams, Pose};

    /// Tape girth of the torso's loop at `z`, found independently of the rays: the field is
    /// sampled on a 1 mm grid, the inside cells connected to the centre are flood-filled, and
    /// the boundary crossings on the grid edges around them (linear interpolation) are hulled.
    fn grid_tape_girth(body: &ImplicitBody, z: f64) -> f64 {
        let (cx, cy) = body.torso_centre(z);
        let (half, step) = (400i32, 1.0);
        let n = (2 * half + 1) as usize;
        let at = |i: i32, j: i32| {
            body.value(DVec3::new(cx + f64::from(i) * step, cy + f64::from(j) * step, z))
        };
        let values: Vec<f64> = (0..n * n)
            .into_par_iter()
            .map(|k| at((k % n) as i32 - half, (k / n) as i32 - half))
            .collect();
        let v = |i: i32, j: i32| values[(j + half) as usize * n + (i + half) as usize];
        let mut inside = vec![false; n * n];
        let mut stack = vec![(0i32, 0i32)];
        let mut crossings = Vec::new();
        while let Some((i, j)) = stack.pop() {
            let k = (j + half) as usize * n + (i + half) as usize;
            if inside[k] {
                continue;
            }
            inside[k] = true;
            for (di, dj) in [(1, 0), (-1, 0), (0, 1), (0, -1)] {
                let (ni, nj) = (i + di, j + dj);
                if ni.abs() > half || nj.abs() > half {
                    continue;
                }
                let (a, b) = (v(i, j), v(ni, nj));
                if b < 0.0 {
                    stack.push((ni, nj));
                } else {
                    let t = a / (a - b);
                    crossings.push([
                        cx + (f64::from(i) + t * f64::from(di)) * step,
                        cy + (f64::from(j) + t * f64::from(dj)) * step,
                    ]);
                }
            }
        }
        perimeter(&convex_hull(&crossings))
    }

    #[test]
    fn ray_marching_finds_the_first_exit() {
        // The marcher steps by half the field's magnitude; a fine fixed-step walk must find
        // the same boundary on every ray.
        let params = BodyParams { pose: Pose::asymmetric_example(), ..BodyParams::default() };
        let a = Anatomy::new(&params);
        let body = ImplicitBody::new(&a, &Calibration::initial(&a));
        for z in a.levels {
            let pts = torso_loop(&body, z).expect("torso loop");
            let (cx, cy) = body.torso_centre(z);
            for (i, p) in pts.iter().enumerate() {
                let angle = i as f64 / RAYS as f64 * std::f64::consts::TAU;
                let (s, c) = angle.sin_cos();
                let mut r = 0.0;
                while body.value(DVec3::new(cx + r * c, cy + r * s, z)) < 0.0 {
                    r += 0.25;
                }
                let found = (p[0] - cx).hypot(p[1] - cy);
                assert!((found - r).abs() <= 0.25, "z {z}, ray {i}: {found} vs {r}");
            }
        }
    }

    #[test]
    fn calibrated_girths_hold_on_an_independent_section() {
        let bodies = [
            BodyParams::default(),
            BodyParams::random(11),
            BodyParams {
                pose: Pose::asymmetric_example(),
                bust_prominence: 1.0,
                ..BodyParams::default()
            },
        ];
        for params in bodies {
            let a = Anatomy::new(&params);
            let c = calibrate(&a).expect("calibrates");
            for l in 0..3 {
                let requested = a.girths[l];
                assert!((c.sections[l].tape / requested - 1.0).abs() < GIRTH_TOLERANCE);
                let independent = grid_tape_girth(&c.body, a.levels[l]);
                let error = independent / requested - 1.0;
                assert!(error.abs() < 0.003, "level {l}: {independent} vs {requested}");
                // The loop is no longer than its contour, and concave only a little.
                let contour = c.sections[l].contour;
                assert!(contour >= c.sections[l].tape - 1e-6 && contour < 1.05 * requested);
            }
            assert!((c.crotch.1 - params.leg_length_mm).abs() < CROTCH_TOLERANCE);
        }
    }
}

#[cfg(test)]
mod level_tests {
    use super::*;
    use crate::params::BodyParams;

    #[test]
    fn levels_are_the_extrema_their_definitions_ask_for() {
        // Chest and hip: the largest girth around their level; waist: the smallest.
        for p in [BodyParams::default(), BodyParams::random(1), BodyParams::random(5)] {
            let a = Anatomy::new(&p);
            let c = calibrate(&a).expect("calibrates");
            let girth = |z: f64| measure_section(&c.body, z).expect("torso loop").tape;
            for (l, sign) in [(0, 1.0), (1, -1.0), (2, 1.0)] {
                let z0 = a.levels[l];
                let at_level = girth(z0);
                for dz in [-20.0, -10.0, 10.0, 20.0] {
                    let g = girth(z0 + dz);
                    assert!(
                        sign * (at_level - g) > -1e-4 * at_level,
                        "level {l} {dz}: {g} vs {at_level}"
                    );
                }
            }
        }
    }
}
