//! Rebuilding a watertight mesh from the symmetric rings (paper Fig. 10).
//!
//! - **Bands**: two neighbouring rings are stitched by one rule ([`stitch`]): each vertex
//!   carries a parameter that runs once around its ring from 0 to 1, both rings starting at
//!   corresponding points, and the band's triangles follow the two rings' vertices in order of
//!   that parameter. Between layers the parameter is the ray index, so ray `i` of one layer
//!   faces ray `i` of the next (a strip of quads, each split along its shorter diagonal).
//!   Where both rings meet the arm plates, their parameters are mapped so that their plate
//!   corners meet ([`band_params`]): the plates' rims run from corner to corner.
//! - **Torso rings** also get a vertex on the symmetry plane at the front and at the back (the
//!   midpoint of the edge that crosses it: no change of shape).
//! - **The crotch** ([`crotch`]): the lowest torso ring sits just above the crotch. A seam
//!   runs on the symmetry plane at the crotch height from that ring's front midline vertex to
//!   its back one. Each leg's top ring is stitched to its half of the lowest torso ring closed
//!   by the seam: each vertex of that half ring takes the parameter of its closest point on
//!   the leg ring (never running backwards), so each part of the thigh meets the part of the
//!   hip or the seam right above it and the band stands upright where the two rings agree.
//!   (Matching the two curves by arc length made the band drift up to 26 mm sideways over its
//!   2 mm of height and fold up to 165 degrees.) Both legs share the seam's edges: one
//!   surface, closed and manifold, with its lowest point on the symmetry plane at the crotch
//!   height.
//! - **Caps** (a fan around the ring's centre, flat) close the neck and the two ankles.

use super::Layer;
use crate::body::mesh::Mesh;
use glam::{DVec2, DVec3};
use std::f64::consts::{PI, TAU};

/// A ring of mesh vertices, closed, counter-clockwise from above, with each vertex's
/// parameter in `[0, 1)` (the first vertex at 0; see the module documentation).
struct Ring {
    vertices: Vec<u32>,
    params: Vec<f64>,
}

impl Ring {
    /// A ring whose vertices are evenly spaced in parameter (the layers' rays).
    fn evenly(vertices: Vec<u32>) -> Ring {
        let n = vertices.len() as f64;
        let params = (0..vertices.len()).map(|k| k as f64 / n).collect();
        Ring { vertices, params }
    }

    /// Parameter of vertex `k`, with `k == len` standing for the first vertex come round again.
    fn param(&self, k: usize) -> f64 {
        if k == self.vertices.len() { 1.0 } else { self.params[k] }
    }
}

/// Adds the points of a ring at height `z`; returns their vertex indices.
fn add_ring(mesh: &mut Mesh, points: &[DVec2], z: f64) -> Vec<u32> {
    let first = mesh.positions.len() as u32;
    mesh.positions.extend(points.iter().map(|p| p.extend(z)));
    (first..mesh.positions.len() as u32).collect()
}

/// Parameters below this difference are equal: the band has a quad there.
const SAME_PARAM: f64 = 1e-12;

/// Stitches ring `lower` to ring `upper` (see the module documentation). Makes
/// `lower.len() + upper.len()` outward-facing triangles.
fn stitch(mesh: &mut Mesh, lower: &Ring, upper: &Ring) {
    let (na, nb) = (lower.vertices.len(), upper.vertices.len());
    let p = |i: u32| mesh.positions[i as usize];
    let (mut i, mut j) = (0, 0);
    let mut triangles = Vec::with_capacity(na + nb);
    while i < na || j < nb {
        let (a, a_next) = (lower.vertices[i % na], lower.vertices[(i + 1) % na]);
        let (b, b_next) = (upper.vertices[j % nb], upper.vertices[(j + 1) % nb]);
        let advance_lower = j == nb
            || (i < na && {
                let (pa, pb) = (lower.param(i + 1), upper.param(j + 1));
                pa < pb - SAME_PARAM
                    || (pa <= pb + SAME_PARAM
                        && p(a_next).distance(p(b)) < p(a).distance(p(b_next)))
            });
        if advance_lower {
            triangles.push([a, a_next, b]);
            i += 1;
        } else {
            triangles.push([a, b_next, b]);
            j += 1;
        }
    }
    mesh.triangles.extend(triangles);
}

/// Closes ring `ring` with a fan around a new vertex at `centre`; `up` for a top cap.
fn cap(mesh: &mut Mesh, ring: &[u32], centre: DVec3, up: bool) {
    let c = mesh.positions.len() as u32;
    mesh.positions.push(centre);
    let n = ring.len();
    for k in 0..n {
        let (a, b) = (ring[k], ring[(k + 1) % n]);
        mesh.triangles.push(if up { [a, b, c] } else { [b, a, c] });
    }
}

/// A torso ring with its front and back vertices on the symmetry plane inserted: the front
/// one first, then the left half (front to back), the back one, the right half (back to front).
/// Returns the ring and the index of the back vertex.
fn with_midline(points: &[DVec3]) -> (Vec<DVec3>, usize) {
    let n = points.len(); // rays - 2
    let half = n / 2; // points per side
    let front = (points[n - 1] + points[0]) * 0.5;
    let back = (points[half - 1] + points[half]) * 0.5;
    let mut out = Vec::with_capacity(n + 2);
    out.push(front);
    out.extend_from_slice(&points[..half]);
    out.push(back);
    out.extend_from_slice(&points[half..]);
    (out, half + 1)
}

/// One torso ring of the mesh: its points (the front midline point first, the left half front
/// to back, the back midline point, the right half back to front), each with its parameter
/// for the bands (never decreasing, the front at 0 and the back at 1/2), and where it meets
/// the arm plates ([`super::arm_plates`]).
pub(super) struct TorsoRing {
    pub points: Vec<DVec3>,
    params: Vec<f64>,
    back: usize,
    /// The plate corners: left front, left back, right back, right front (ring order).
    pub corners: Option<[usize; 4]>,
}

impl TorsoRing {
    /// The ring of the `rays - 2` points of a layer's rays (paper eq. 7, see
    /// [`crate::shape::symmetry`]), lifted onto its surface; each point's parameter is its ray's.
    pub fn from_rays(points: &[DVec3]) -> TorsoRing {
        let (points, back) = with_midline(points);
        let n = points.len() as f64;
        let params = (0..points.len()).map(|k| k as f64 / n).collect();
        TorsoRing { points, params, back, corners: None }
    }

    /// The horizontal ring at height `z` of `points` (counter-clockwise from above, the left
    /// half first, as the rays' are), mirror-symmetric about the plane x = `axis`, whose chords
    /// on the left and right plates run between the indices `chords` (left first); each
    /// point's parameter is its direction from `centre` (as a ray's is).
    pub fn with_corners(
        mut points: Vec<DVec2>,
        z: f64,
        centre: DVec2,
        axis: f64,
        chords: &[(usize, usize)],
    ) -> TorsoRing {
        // The front midline point between the last point and the first, the back one where the
        // ring crosses the plane from the left half to the right.
        let n = points.len();
        let cross = (0..n - 1)
            .find(|&k| points[k].x > axis && points[k + 1].x <= axis)
            .unwrap_or(n / 2 - 1);
        let front = (points[n - 1] + points[0]) * 0.5;
        let back = (points[cross] + points[cross + 1]) * 0.5;
        points.insert(cross + 1, back);
        points.insert(0, front);
        let back = cross + 2;
        let moved = |k: usize| if k > cross { k + 2 } else { k + 1 };
        let corners = match chords {
            &[(a, b), (c, d)] => Some([a, b, c, d].map(moved)),
            _ => None,
        };
        // Directions from the centre, kept from running backwards where a chord point was laid
        // on its plate across a ray.
        let mut params: Vec<f64> = Vec::with_capacity(points.len());
        for (k, &p) in points.iter().enumerate() {
            let d = match k {
                0 => 0.0,
                k if k == back => 0.5,
                _ => direction_param(p - centre).max(params[k - 1]),
            };
            params.push(d);
        }
        TorsoRing { points: points.iter().map(|p| p.extend(z)).collect(), params, back, corners }
    }
}

/// The parameter of direction `d` in the plane: 0 to the front (-Y), growing counter-clockwise
/// from above to 1 (as the rays', [`crate::shape::symmetry::rays::direction`]).
fn direction_param(d: DVec2) -> f64 {
    ((d.y.atan2(d.x) - 1.5 * PI) / TAU).rem_euclid(1.0)
}

/// The parameters of the neighbouring torso rings `a` and `b` for the band between them:
/// where both meet the arm plates, mapped piecewise linearly so that their corners (and the
/// front and back midlines) fall together at the mean of their own, so corner meets corner
/// (see [`super::arm_plates`]); elsewhere their own.
fn band_params(a: &TorsoRing, b: &TorsoRing) -> [Vec<f64>; 2] {
    let (Some(ca), Some(cb)) = (a.corners, b.corners) else {
        return [a.params.clone(), b.params.clone()];
    };
    let anchors = |r: &TorsoRing, c: [usize; 4]| {
        [0.0, r.params[c[0]], r.params[c[1]], 0.5, r.params[c[2]], r.params[c[3]], 1.0]
    };
    let (from_a, from_b) = (anchors(a, ca), anchors(b, cb));
    let target: Vec<f64> = from_a.iter().zip(&from_b).map(|(x, y)| 0.5 * (x + y)).collect();
    let remap = |r: &TorsoRing, from: &[f64]| -> Vec<f64> {
        r.params
            .iter()
            .map(|&p| {
                let i = (0..from.len() - 2).find(|&i| p <= from[i + 1]).unwrap_or(from.len() - 2);
                let span = from[i + 1] - from[i];
                let s = if span > 0.0 { (p - from[i]) / span } else { 0.0 };
                target[i] + s * (target[i + 1] - target[i])
            })
            .collect()
    };
    [remap(a, &from_a), remap(b, &from_b)]
}

/// Cumulative arc length around the closed ring `points`: `len + 1` values from 0 to the
/// perimeter.
fn arc_lengths(points: &[DVec2]) -> Vec<f64> {
    let n = points.len();
    let mut s = Vec::with_capacity(n + 1);
    s.push(0.0);
    for k in 0..n {
        s.push(s[k] + points[k].distance(points[(k + 1) % n]));
    }
    s
}

/// Arc-length parameters (`[0, 1)`, from vertex 0) of the vertices of the closed ring
/// `points`.
fn arc_params(points: &[DVec2]) -> Vec<f64> {
    let s = arc_lengths(points);
    let total = s[points.len()].max(f64::MIN_POSITIVE);
    s[..points.len()].iter().map(|l| l / total).collect()
}

/// The point of the closed ring `curve` closest to `p`: (the index of the edge it lies on,
/// its fraction along that edge, the point).
pub(super) fn closest_on_ring(curve: &[DVec2], p: DVec2) -> (usize, f64, DVec2) {
    let n = curve.len();
    let mut best = (0, 0.0, curve[0]);
    for k in 0..n {
        let (a, b) = (curve[k], curve[(k + 1) % n]);
        let ab = b - a;
        let t = ((p - a).dot(ab) / ab.length_squared().max(f64::MIN_POSITIVE)).clamp(0.0, 1.0);
        let q = a + ab * t;
        if q.distance_squared(p) < best.2.distance_squared(p) {
            best = (k, t, q);
        }
    }
    best
}

/// The arc-length parameter (`[0, 1)`, from vertex 0) of the point of the closed ring `curve`
/// (cumulative arc lengths `s`) closest to `p`.
fn closest_param(curve: &[DVec2], s: &[f64], p: DVec2) -> f64 {
    let (k, t, _) = closest_on_ring(curve, p);
    (s[k] + t * (s[k + 1] - s[k])) / s[curve.len()].max(f64::MIN_POSITIVE)
}

/// Parameters of the closed ring `points` (starting where `curve` starts) read off the
/// closed ring `curve` below it: each vertex takes the arc-length parameter of its closest
/// point on `curve`, kept from running backwards (a vertex whose closest point lies behind
/// its predecessor's takes the predecessor's parameter: a fan). So each part of the one ring
/// meets the part of the other right beside it, and the band between them stands upright
/// where the rings agree instead of drifting sideways along them.
fn projected_params(points: &[DVec2], curve: &[DVec2]) -> Vec<f64> {
    let s = arc_lengths(curve);
    let mut params = Vec::with_capacity(points.len());
    let mut previous = 0.0;
    for (k, &p) in points.iter().enumerate() {
        let raw = closest_param(curve, &s, p);
        // The parameter wraps at the start: take the reading nearest to the predecessor's.
        let unwrapped = [raw - 1.0, raw, raw + 1.0]
            .into_iter()
            .min_by(|a, b| (a - previous).abs().total_cmp(&(b - previous).abs()))
            .expect("three readings");
        previous = if k == 0 { 0.0 } else { unwrapped.clamp(previous, 1.0) };
        params.push(previous);
    }
    params
}

/// Index of the point of `points` nearest to `p`.
fn nearest(points: &[DVec2], p: DVec2) -> usize {
    (0..points.len())
        .min_by(|&a, &b| points[a].distance_squared(p).total_cmp(&points[b].distance_squared(p)))
        .expect("a ring has points")
}

/// Stitches a leg's top ring (`leg`, vertex indices, counter-clockwise from above) to
/// `boundary`: its half of the lowest torso ring closed by the seam, starting at the seam's
/// front end (see the module documentation).
fn join_leg(mesh: &mut Mesh, leg: &[u32], boundary: Vec<u32>) {
    let flat = |vs: &[u32]| -> Vec<DVec2> {
        vs.iter().map(|&v| mesh.positions[v as usize].truncate()).collect()
    };
    let (leg_points, boundary_points) = (flat(leg), flat(&boundary));
    let n = leg.len();
    let front_anchor = nearest(&leg_points, boundary_points[0]);
    let rotated: Vec<u32> = (0..n).map(|k| leg[(front_anchor + k) % n]).collect();
    let rotated_points = flat(&rotated);
    let leg_params = arc_params(&rotated_points);
    let boundary_params = projected_params(&boundary_points, &rotated_points);
    stitch(
        mesh,
        &Ring { vertices: rotated, params: leg_params },
        &Ring { vertices: boundary, params: boundary_params },
    );
}

/// The crotch (see the module documentation): the seam on the plane x = `axis` at height
/// `crotch` from the front to the back vertex of the lowest torso ring `ring0` (whose back
/// vertex is at `back`), and the two legs' top rings joined to it.
fn crotch(
    mesh: &mut Mesh,
    ring0: &[u32],
    back: usize,
    [left_top, right_top]: [&[u32]; 2],
    axis: f64,
    crotch: f64,
) {
    let (front_p, back_p) =
        (mesh.positions[ring0[0] as usize], mesh.positions[ring0[back] as usize]);
    // Seam points as far apart as the ring's points.
    let spacing = (0..back).map(|k| {
        let (a, b) = (mesh.positions[ring0[k] as usize], mesh.positions[ring0[k + 1] as usize]);
        a.truncate().distance(b.truncate())
    });
    let spacing = spacing.sum::<f64>() / back as f64;
    let count = ((back_p.y - front_p.y) / spacing).round().max(1.0) as usize;
    let seam: Vec<u32> = (1..count)
        .map(|k| {
            let y = front_p.y + (back_p.y - front_p.y) * k as f64 / count as f64;
            mesh.positions.push(DVec3::new(axis, y, crotch));
            (mesh.positions.len() - 1) as u32
        })
        .collect();
    // Left: front, the left half, back, the seam back to front.
    let mut left: Vec<u32> = ring0[..=back].to_vec();
    left.extend(seam.iter().rev());
    // Right: front, the seam front to back, back, the right half.
    let mut right: Vec<u32> = vec![ring0[0]];
    right.extend(&seam);
    right.extend(&ring0[back..]);
    join_leg(mesh, left_top, left);
    join_leg(mesh, right_top, right);
}

/// The mannequin mesh from its torso rings (bottom to top, see [`super::shoulder_cap`] and
/// [`super::arm_plates`]) closed by the neck cap around `neck_centre`, its leg layers (each
/// list bottom to top), its symmetry plane and the crotch height.
pub(super) fn rebuild(
    torso: &[TorsoRing],
    neck_centre: DVec3,
    left: &[Layer],
    right: &[Layer],
    axis: f64,
    crotch_z: f64,
) -> Mesh {
    let mut mesh = Mesh::default();

    let torso_rings: Vec<Vec<u32>> = torso
        .iter()
        .map(|ring| {
            let first = mesh.positions.len() as u32;
            mesh.positions.extend(&ring.points);
            (first..mesh.positions.len() as u32).collect()
        })
        .collect();
    for (k, pair) in torso.windows(2).enumerate() {
        let [lower, upper] = band_params(&pair[0], &pair[1]);
        stitch(
            &mut mesh,
            &Ring { vertices: torso_rings[k].clone(), params: lower },
            &Ring { vertices: torso_rings[k + 1].clone(), params: upper },
        );
    }
    cap(&mut mesh, torso_rings.last().expect("at least two torso rings"), neck_centre, true);

    let mut leg_tops = Vec::with_capacity(2);
    for leg in [left, right] {
        let rings: Vec<Ring> =
            leg.iter().map(|l| Ring::evenly(add_ring(&mut mesh, &l.points, l.z))).collect();
        for pair in rings.windows(2) {
            stitch(&mut mesh, &pair[0], &pair[1]);
        }
        let bottom = &leg[0];
        cap(
            &mut mesh,
            &rings[0].vertices,
            DVec3::new(bottom.centre[0], bottom.centre[1], bottom.z),
            false,
        );
        leg_tops.push(rings.last().expect("at least two leg layers").vertices.clone());
    }
    crotch(&mut mesh, &torso_rings[0], torso[0].back, [&leg_tops[0], &leg_tops[1]], axis, crotch_z);
    mesh
}
