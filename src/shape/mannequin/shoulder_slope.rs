//! A dress form's shoulder: the shoulder top never flatter than [`MIN_SLOPE_DEG`].
//!
//! Some bodies have a shelf over the shoulders: MakeHuman's base body rises 60 mm from its
//! shoulder point to the side of its neck, a 22-degree shoulder slope as a tailor measures it
//! (neck side to shoulder point, [`crate::shape::measure`]), but its shoulder top is level for 45 mm
//! beside the neck (the trapezius). A level top makes a horizontal slice's width jump by the
//! whole shelf between two slices 2 mm apart (130 mm there), and a level shoulder meets the arm
//! plate in a square corner. A dress form's shoulder line runs straight from the neck to the
//! shoulder point instead.
//!
//! So the mesh above the shoulder points ([`super::shoulder_cap`]) is raised where its top is
//! flatter than [`MIN_SLOPE_DEG`]: the front silhouette's top `s(u)` (the highest point at each
//! distance `u` from the symmetry plane) is replaced by the lowest profile above it that rises
//! inwards at least at that slope,
//!
//! `t(u) = max over v >= u of s(v) + (v - u) tan(MIN_SLOPE_DEG)`,
//!
//! and each point at `(u, z)` rises by `(t(u) - s(u))` times a smooth step from 0 at the
//! cap's start to 1 at the top, so the column below stretches and nothing folds. The shoulder
//! points and the side of the neck stay where they are (`t = s` at both), and so does the
//! tailor's shoulder slope: the straight line between them lies above `t`. Beside the neck,
//! where the lift falls to nothing, it is spread out (a Gaussian of [`LIFT_SIGMA_MM`]), so the
//! raised top meets the neck's side in a curve. Where the body's shoulder is as steep as a
//! dress form's (most adults), nothing moves: the generator's bodies, whose shoulders slope
//! 14-20 degrees, moved by a few tenths of a millimetre at 16 degrees; at 16.5 their shoulder
//! lines stay within 4.5 mm of the body's (mannequin_quality's 20 random customers).
//!
//! The silhouette is the mesh's own, its edges': edges that span more than [`MAX_SPAN_MM`]
//! across the shoulder are halved first, so there is a vertex to raise wherever the top must
//! rise, and a vertex below the top of its column (raised less than the top) may still carry
//! an edge of the silhouette, so the raising repeats until the top is within
//! [`CLOSE_ENOUGH_MM`] of `t`. The mesh is raised, not the torso layers: those are the paper's
//! horizontal sections (`profiles.json`), as the cap's bent rings already are not.

use super::smoothstep;
use crate::body::mesh::Mesh;
use glam::DVec3;
use std::cmp::Reverse;
use std::collections::{BinaryHeap, HashMap};

/// The flattest shoulder top the mannequin has (degrees from horizontal). Flatter than
/// 14.9 degrees, the width of horizontal slices 2 mm apart jumps by more than 15 mm, the most a
/// smooth body's does (issue 12); the margin leaves room for the mesh's straight segments
/// between rings and for the curve where the top meets the neck. At 16 degrees the largest
/// jumps of issue 35's 40 MakeHuman bodies were 14.0-15.0 mm (at the limit); at 17, one of
/// the generator's random customers had its shoulder line raised 5.2 mm over the body's
/// (the limit is 5); at 16.5 the population's largest jump is 14.6 mm and that customer's
/// shoulder line 4.5 mm off.
const MIN_SLOPE_DEG: f64 = 16.5;

/// How far (mm) the lift is spread across the shoulder where it starts and ends: about a
/// quarter of the shoulder's width beside the neck (50-60 mm on adults), so the raised top
/// meets the body's and the neck's in a curve.
const LIFT_SIGMA_MM: f64 = 12.0;

/// Passes that raise the top at most (see [`steepen`]): on MakeHuman's shoulders the top was
/// 18.0 mm short of the sloped profile before the first, 1.3 after it, then 0.4 and 0.2 (its
/// width jump 14.1 mm; measured at 16 degrees).
const MAX_PASSES: usize = 4;

/// The top is raised enough when it is this close to the sloped profile (mm).
const CLOSE_ENOUGH_MM: f64 = 0.05;

/// The longest an edge above the cap's start may reach across the shoulder (mm, in distance
/// from the symmetry plane) before it is halved ([`bisect_long_edges`]): where the first
/// nearly level rings of the cap cross a level shoulder top, one edge spanned 90 mm of it
/// (the posed MakeHuman body), and a raised vertex cannot straighten an edge's middle.
const MAX_SPAN_MM: f64 = 8.0;

/// An edge reaches above the cap's start when it reaches this far above it (mm): the
/// midpoints of its lowest ring's edges round a few 1e-11 mm either way.
const ABOVE_MM: f64 = 1e-6;

/// A triangle this small (mm²) has no area.
const DEGENERATE_MM2: f64 = 1e-9;

/// The neck cap's vertices lie within this of the mesh's top (mm): it is flat.
const NECK_CAP_MM: f64 = 1e-6;

/// The width of the bins in which the silhouette's top is found (mm): finer than the rings'
/// points (1 degree of a 150 mm shoulder apart, 2.6 mm).
const BIN_MM: f64 = 0.5;

/// The silhouette's top over `u` (distance from the plane x = `axis`) of the `triangles` of
/// `mesh`, in bins of [`BIN_MM`] from 0: the highest point of their edges (a triangle's
/// highest point at any `u` is on one of them). Bins no edge reaches are interpolated.
fn silhouette_top(mesh: &Mesh, triangles: &[usize], axis: f64) -> Vec<f64> {
    let u = |p: DVec3| (p.x - axis).abs();
    let triangles: Vec<[DVec3; 3]> =
        triangles.iter().map(|&t| mesh.triangles[t].map(|v| mesh.positions[v as usize])).collect();
    let reach = triangles.iter().flatten().map(|&p| u(p)).fold(0.0, f64::max);
    let mut top = vec![f64::NEG_INFINITY; (reach / BIN_MM).ceil() as usize + 1];
    for [a, b, c] in triangles {
        for (p, q) in [(a, b), (b, c), (c, a)] {
            let (up, uq) = (u(p), u(q));
            let (lo, hi) = ((up.min(uq) / BIN_MM).ceil() as usize, (up.max(uq) / BIN_MM) as usize);
            for (bin, top) in top.iter_mut().enumerate().take(hi + 1).skip(lo) {
                let s = if uq == up { 0.0 } else { (bin as f64 * BIN_MM - up) / (uq - up) };
                *top = top.max(p.z + (q.z - p.z) * s.clamp(0.0, 1.0));
            }
        }
    }
    fill_gaps(&mut top);
    top
}

/// The triangles of `mesh` with a corner above `from`.
fn reaching_above(mesh: &Mesh, from: f64) -> Vec<usize> {
    let above = |t: &[u32; 3]| t.iter().any(|&v| mesh.positions[v as usize].z > from);
    (0..mesh.triangles.len()).filter(|&t| above(&mesh.triangles[t])).collect()
}

/// Replaces the non-finite entries of `values` by linear interpolation between their finite
/// neighbours (or the nearest finite one at either end).
fn fill_gaps(values: &mut [f64]) {
    let known: Vec<usize> = (0..values.len()).filter(|&i| values[i].is_finite()).collect();
    let (Some(&first), Some(&last)) = (known.first(), known.last()) else { return };
    for pair in known.windows(2) {
        let (a, b) = (pair[0], pair[1]);
        for i in a + 1..b {
            values[i] = values[a] + (values[b] - values[a]) * (i - a) as f64 / (b - a) as f64;
        }
    }
    let (head, tail) = (values[first], values[last]);
    values[..first].fill(head);
    values[last + 1..].fill(tail);
}

/// The lowest profile at or above `top` (bins of [`BIN_MM`]) that rises inwards by at least
/// `rise` per mm: `t(u) = max over v >= u of top(v) + (v - u) rise`.
fn sloped_envelope(top: &[f64], rise: f64) -> Vec<f64> {
    let mut t = top.to_vec();
    for bin in (0..t.len().saturating_sub(1)).rev() {
        t[bin] = t[bin].max(t[bin + 1] + rise * BIN_MM);
    }
    t
}

/// The value of the binned profile `values` at `u` (linear between bins).
fn at(values: &[f64], u: f64) -> f64 {
    let s = (u / BIN_MM).clamp(0.0, (values.len() - 1) as f64);
    let (i, f) = (s.floor() as usize, s.fract());
    let next = values[(i + 1).min(values.len() - 1)];
    values[i] + (next - values[i]) * f
}

/// Raises the shoulder top of the mannequin `mesh` (about the plane x = `axis`, its rings
/// bent over the shoulders from height `from` up, closed by the flat neck cap at its top)
/// where it is flatter than [`MIN_SLOPE_DEG`] (see the module documentation); the vertices
/// for which `fixed` holds (on the arm plates) stay, and so does the neck: nothing within the
/// neck cap's width moves, and nothing rises above it.
pub(super) fn steepen(mesh: &mut Mesh, axis: f64, from: f64, fixed: &dyn Fn(DVec3) -> bool) {
    let neck_top = mesh.positions.iter().map(|p| p.z).fold(f64::NEG_INFINITY, f64::max);
    let neck_half = mesh
        .positions
        .iter()
        .filter(|p| p.z >= neck_top - NECK_CAP_MM)
        .map(|p| (p.x - axis).abs())
        .fold(0.0, f64::max);
    bisect_long_edges(mesh, axis, from, fixed);
    // Raised, they stay above `from`.
    let cap = reaching_above(mesh, from);
    let rise = MIN_SLOPE_DEG.to_radians().tan();
    // A vertex below the top is raised less than the top, and an edge from it may be the
    // silhouette: each pass leaves a fraction of the shortfall, the next one raises it again.
    let mut shortfall = f64::INFINITY;
    for _ in 0..MAX_PASSES {
        let top = silhouette_top(mesh, &cap, axis);
        let least: Vec<f64> = sloped_envelope(&top, rise)
            .iter()
            .zip(&top)
            .map(|(t, s)| (t.min(neck_top) - s).max(0.0))
            .collect();
        // A shortfall no pass reduces is where nothing may move (at the arm plates' top).
        let worst = least.iter().fold(0.0, |a: f64, &b| a.max(b));
        if worst <= CLOSE_ENOUGH_MM || worst >= shortfall {
            break;
        }
        shortfall = worst;
        // Inside the largest lift, where the least lift falls to nothing beside the neck, its
        // smoothed value takes over where that is more (faded out at the neck): the raised top
        // meets the neck's side in a curve, not a crease. (Outside it, towards the shoulder
        // point, a smoothed lift would flatten the top where it starts to rise.)
        let smooth = gaussian(&least, LIFT_SIGMA_MM / BIN_MM);
        let peak = (0..least.len()).max_by(|&a, &b| least[a].total_cmp(&least[b])).unwrap_or(0);
        let lift: Vec<f64> = (0..least.len())
            .map(|i| {
                let faded = smooth[i] * smoothstep((i as f64 * BIN_MM - neck_half) / LIFT_SIGMA_MM);
                if i < peak { least[i].max(faded) } else { least[i] }
            })
            .collect();
        for p in mesh.positions.iter_mut().filter(|p| !fixed(**p)) {
            let u = (p.x - axis).abs();
            let (s, lift) = (at(&top, u), at(&lift, u));
            if lift > 0.0 && s > from && u > neck_half {
                p.z += lift * smoothstep((p.z - from) / (s - from));
            }
        }
    }
}

/// Halves every edge of `mesh` that reaches above `from` and spans more than [`MAX_SPAN_MM`]
/// across the shoulder, until none does (longest first; both triangles beside an edge are
/// split through its middle, so the mesh stays closed and its surface unchanged). Edges
/// between two `fixed` vertices (on a flat arm plate) stay.
fn bisect_long_edges(mesh: &mut Mesh, axis: f64, from: f64, fixed: &dyn Fn(DVec3) -> bool) {
    let key = |a: u32, b: u32| (a.min(b), a.max(b));
    let mut beside: HashMap<(u32, u32), Vec<usize>> = HashMap::new();
    // An edge reaching above `from` has both its triangles among those that do.
    for t in reaching_above(mesh, from) {
        let tri = mesh.triangles[t];
        for k in 0..3 {
            beside.entry(key(tri[k], tri[(k + 1) % 3])).or_default().push(t);
        }
    }
    let span = |mesh: &Mesh, (a, b): (u32, u32)| {
        let (p, q) = (mesh.positions[a as usize], mesh.positions[b as usize]);
        let long = ((p.x - axis).abs() - (q.x - axis).abs()).abs() > MAX_SPAN_MM;
        (long && p.z.max(q.z) > from + ABOVE_MM && !(fixed(p) && fixed(q))).then(|| p.distance(q))
    };
    // Longest first (a positive length's bits order as the length), ties in a fixed order:
    // mirror partners are split alike. An edge already split is skipped when it comes up.
    let mut queue: BinaryHeap<(u64, Reverse<(u32, u32)>)> =
        beside.keys().filter_map(|&e| span(mesh, e).map(|l| (l.to_bits(), Reverse(e)))).collect();
    while let Some((_, Reverse((a, b)))) = queue.pop() {
        let Some(triangles) = beside.remove(&(a, b)) else { continue };
        // A triangle with no area (three points of one straight ring) has its third corner on
        // the edge's line: halving would only make another edge as long along it.
        if triangles.iter().any(|&t| mesh.triangle_area(t) <= DEGENERATE_MM2) {
            beside.insert((a, b), triangles);
            continue;
        }
        let m = mesh.positions.len() as u32;
        mesh.positions.push(0.5 * (mesh.positions[a as usize] + mesh.positions[b as usize]));
        for t in triangles {
            let tri = mesh.triangles[t];
            let k = (0..3).find(|&k| key(tri[k], tri[(k + 1) % 3]) == (a, b)).expect("its edge");
            let (p, q, r) = (tri[k], tri[(k + 1) % 3], tri[(k + 2) % 3]);
            let new = mesh.triangles.len();
            mesh.triangles[t] = [p, m, r];
            mesh.triangles.push([m, q, r]);
            if let Some(list) = beside.get_mut(&key(q, r)) {
                list.iter_mut().filter(|x| **x == t).for_each(|x| *x = new);
            }
            beside.entry(key(p, m)).or_default().push(t);
            beside.entry(key(m, q)).or_default().push(new);
            beside.entry(key(m, r)).or_default().extend([t, new]);
            for e in [key(p, m), key(m, q), key(m, r)] {
                queue.extend(span(mesh, e).map(|l| (l.to_bits(), Reverse(e))));
            }
        }
    }
}

/// `values` smoothed by a Gaussian of deviation `sigma` bins (cut at three deviations; the
/// ends are held).
fn gaussian(values: &[f64], sigma: f64) -> Vec<f64> {
    let reach = (3.0 * sigma).ceil() as isize;
    let weights: Vec<f64> =
        (-reach..=reach).map(|d| (-0.5 * (d as f64 / sigma).powi(2)).exp()).collect();
    let total: f64 = weights.iter().sum();
    let last = values.len() as isize - 1;
    (0..values.len() as isize)
        .map(|i| {
            let sum: f64 = (-reach..=reach)
                .zip(&weights)
                .map(|(d, w)| w * values[(i + d).clamp(0, last) as usize])
                .sum();
            sum / total
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A closed mesh of horizontal rings of `n` points from height `from` to `top` every
    /// 2 mm, each an ellipse of half-axes `a(z)` (x) and `0.3 a(z)` (y), capped flat at the top
    /// (the neck) and the bottom.
    fn body(n: usize, from: f64, top: f64, a: impl Fn(f64) -> f64) -> Mesh {
        let count = ((top - from) / 2.0).round() as usize + 1;
        let mut positions: Vec<DVec3> = (0..count)
            .flat_map(|k| {
                let z = from + 2.0 * k as f64;
                let a = a(z);
                (0..n).map(move |i| {
                    let phi = std::f64::consts::TAU * i as f64 / n as f64;
                    DVec3::new(a * phi.cos(), 0.3 * a * phi.sin(), z)
                })
            })
            .collect();
        let v = |k: usize, i: usize| (k * n + i % n) as u32;
        let mut triangles = Vec::new();
        for k in 0..count - 1 {
            for i in 0..n {
                triangles.push([v(k, i), v(k, i + 1), v(k + 1, i + 1)]);
                triangles.push([v(k, i), v(k + 1, i + 1), v(k + 1, i)]);
            }
        }
        for (k, z) in [(0, from), (count - 1, top)] {
            let centre = positions.len() as u32;
            positions.push(DVec3::new(0.0, 0.0, z));
            triangles.extend((0..n).map(|i| [centre, v(k, i), v(k, i + 1)]));
        }
        Mesh::new(positions, triangles)
    }

    /// Linear from `(z0, a0)` to `(z1, a1)`.
    fn ramp(z: f64, (z0, a0): (f64, f64), (z1, a1): (f64, f64)) -> f64 {
        a0 + (a1 - a0) * (z - z0) / (z1 - z0)
    }

    /// The rise per mm of the binned profile `t` between `u0` and `u1`.
    fn slope(t: &[f64], u0: f64, u1: f64) -> f64 {
        (at(t, u0) - at(t, u1)) / (u1 - u0)
    }

    /// The largest height change of the vertices of `a` and `b` for which `which` holds.
    fn moved(a: &Mesh, b: &Mesh, which: impl Fn(DVec3) -> bool) -> f64 {
        let pairs = a.positions.iter().zip(&b.positions).filter(|(p, _)| which(**p));
        pairs.map(|(p, q)| (p.z - q.z).abs()).fold(0.0, f64::max)
    }

    #[test]
    fn a_level_shelf_is_raised_to_the_slope_and_the_ends_stay() {
        // Below the shoulder point (200 mm out, at 60) the side is vertical; the shoulder
        // rises at 45 degrees to 160 mm out, then 4 mm over a shelf to 80 mm out (3 degrees),
        // then steeply up the side of the neck (60 mm out at 200).
        let from = 40.0;
        let half_width = |z: f64| match z {
            z if z < 60.0 => 200.0,
            z if z < 100.0 => ramp(z, (60.0, 200.0), (100.0, 160.0)),
            z if z < 104.0 => ramp(z, (100.0, 160.0), (104.0, 80.0)),
            z => ramp(z, (104.0, 80.0), (200.0, 60.0)),
        };
        let mut mesh = body(720, from, 200.0, half_width);
        let unmoved = mesh.clone();
        let before = silhouette_top(&mesh, &reaching_above(&mesh, from), 0.0);
        assert!(slope(&before, 90.0, 150.0) < 0.06, "the shelf is nearly level");
        steepen(&mut mesh, 0.0, from, &|_| false);
        let after = silhouette_top(&mesh, &reaching_above(&mesh, from), 0.0);
        let rise = MIN_SLOPE_DEG.to_radians().tan();
        for u in [90.0, 120.0, 150.0] {
            assert!(slope(&after, u - 5.0, u + 5.0) >= rise - 1e-3, "flat at {u}");
        }
        // The shoulder point, the neck and the cap's start do not move.
        for u in [30.0, 59.0, 199.0] {
            assert!((at(&after, u) - at(&before, u)).abs() < 1e-9, "moved at {u}");
        }
        assert_eq!(moved(&mesh, &unmoved, |p| p.z <= from), 0.0, "the lowest ring stays");
        assert!(moved(&mesh, &unmoved, |_| true) > 10.0, "the shelf is raised");
    }

    #[test]
    fn a_shoulder_steeper_than_the_slope_does_not_move() {
        // A straight shoulder line from 200 mm out at 40 to the neck, 60 mm out at 200: 49
        // degrees.
        let mut mesh = body(720, 40.0, 200.0, |z| ramp(z, (40.0, 200.0), (200.0, 60.0)));
        let before = mesh.clone();
        steepen(&mut mesh, 0.0, 40.0, &|_| false);
        assert!(moved(&mesh, &before, |_| true) < 1e-9);
    }

    #[test]
    fn vertices_held_fixed_stay() {
        let mut mesh = body(720, 40.0, 200.0, |z| if z < 104.0 { 200.0 } else { 60.0 });
        let before = mesh.clone();
        steepen(&mut mesh, 0.0, 40.0, &|p| p.x > 0.0);
        assert_eq!(moved(&mesh, &before, |p| p.x > 0.0), 0.0);
        assert!(moved(&mesh, &before, |_| true) > 10.0, "the other side is raised");
    }

    #[test]
    fn long_edges_are_halved_and_the_mesh_stays_closed() {
        let mut mesh = body(72, 40.0, 200.0, |z| if z < 104.0 { 200.0 } else { 60.0 });
        let (area, volume) = (mesh.area(), mesh.signed_volume());
        bisect_long_edges(&mut mesh, 0.0, 40.0, &|_| false);
        assert!((mesh.area() - area).abs() < 1e-6 * area, "the surface is unchanged");
        assert!((mesh.signed_volume() - volume).abs() < 1e-6 * volume.abs());
        let mut uses: HashMap<(u32, u32), usize> = HashMap::new();
        for t in &mesh.triangles {
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                *uses.entry((a.min(b), a.max(b))).or_default() += 1;
                let (p, q) = (mesh.positions[a as usize], mesh.positions[b as usize]);
                let long = (p.x.abs() - q.x.abs()).abs() > MAX_SPAN_MM;
                assert!(!long || p.z.max(q.z) <= 40.0 + ABOVE_MM, "a long edge {p} {q}");
            }
        }
        assert!(uses.values().all(|&n| n == 2), "every edge between two triangles");
    }

    #[test]
    fn a_triangle_without_area_does_not_halve_forever() {
        // Three points of the cap's lowest ring on one straight line (the posed MakeHuman
        // body's, at 1377 mm), one of them a midpoint rounded one step above the others, and a
        // point above: each half of the edge to the far point made another such edge as long
        // along the line.
        let from: f64 = 1376.6970383574264;
        let up = f64::from_bits(from.to_bits() + 1);
        let on_line = |x: f64| DVec3::new(x, 3.0 - 8.0 * (x - 107.0) / 44.0, from);
        let positions = vec![
            on_line(107.0),
            on_line(151.0),
            DVec3 { z: up, ..on_line(121.8) },
            DVec3::new(130.0, 20.0, from + 10.0),
        ];
        let mut mesh = Mesh::new(positions, vec![[2, 0, 1], [3, 2, 1], [0, 2, 3]]);
        let (done, finished) = std::sync::mpsc::channel();
        std::thread::spawn(move || {
            bisect_long_edges(&mut mesh, 0.0, from, &|_| false);
            done.send(mesh.triangles.len()).expect("the test waits");
        });
        let deadline = std::time::Duration::from_secs(10);
        assert!(finished.recv_timeout(deadline).is_ok(), "still halving after 10 s");
    }
}
