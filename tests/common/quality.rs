//! Checks of a mannequin a tailor (and a CAD tool) would accept: no width jump between
//! horizontal slices, no self-intersecting triangles, no ledge at the crotch, and the shoulder
//! line of the front silhouette. Independent of the library's own geometry code, except for
//! slicing.

use dressform::body::mesh::Mesh;
use dressform::body::slice::sections;
use glam::DVec3;
use robust::{Coord, Coord3D, orient2d, orient3d};
use rstar::RTree;
use rstar::primitives::{GeomWithData, Rectangle};
use std::collections::HashMap;

/// The spacing of the slices the width jump compares (mm), from the definition.
pub const WIDTH_JUMP_STEP_MM: f64 = 2.0;

/// The largest change of left-right width between horizontal slices `WIDTH_JUMP_STEP_MM`
/// apart, over every pair of slices that both cut the mesh between heights `lo` and `hi`:
/// (jump in mm, height of the lower slice). A smooth body stays under 15 mm.
pub fn width_jump(mesh: &Mesh, lo: f64, hi: f64) -> (f64, f64) {
    let b = mesh.bounds().expect("a mesh");
    let (lo, hi) = (lo.max(b.min.z), hi.min(b.max.z));
    let n = ((hi - lo - WIDTH_JUMP_STEP_MM) / WIDTH_JUMP_STEP_MM).floor().max(0.0) as usize;
    let heights: Vec<f64> =
        (0..=n).map(|k| lo + 0.5 * WIDTH_JUMP_STEP_MM + k as f64 * WIDTH_JUMP_STEP_MM).collect();
    let widths: Vec<(f64, Option<f64>)> = sections(mesh, &heights)
        .iter()
        .map(|s| {
            let xs = s.loops.iter().flat_map(|l| l.points.iter().map(|p| p.x));
            let (lo, hi) =
                xs.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), x| (lo.min(x), hi.max(x)));
            (s.height, (hi >= lo).then_some(hi - lo))
        })
        .collect();
    widths
        .windows(2)
        .filter_map(|w| Some(((w[1].1? - w[0].1?).abs(), w[0].0)))
        .fold((0.0, f64::NAN), |best, j| if j.0 > best.0 { j } else { best })
}

fn c3(p: DVec3) -> Coord3D<f64> {
    Coord3D { x: p.x, y: p.y, z: p.z }
}

/// Exact sign of the orientation of `d` against the plane through `a`, `b`, `c`.
fn orient(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> i8 {
    let o = orient3d(c3(a), c3(b), c3(c), c3(d));
    if o > 0.0 {
        1
    } else if o < 0.0 {
        -1
    } else {
        0
    }
}

/// Drops the coordinate along which the plane of `t` is steepest, for exact 2D tests on
/// coplanar figures (orientation in 2D is then exact too).
fn project(t: [DVec3; 3], points: &[DVec3]) -> Vec<Coord<f64>> {
    let n = (t[1] - t[0]).cross(t[2] - t[0]).abs();
    let drop = if n.x >= n.y && n.x >= n.z {
        0
    } else if n.y >= n.z {
        1
    } else {
        2
    };
    points
        .iter()
        .map(|p| match drop {
            0 => Coord { x: p.y, y: p.z },
            1 => Coord { x: p.z, y: p.x },
            _ => Coord { x: p.x, y: p.y },
        })
        .collect()
}

fn sign2(a: Coord<f64>, b: Coord<f64>, c: Coord<f64>) -> i8 {
    let o = orient2d(a, b, c);
    if o > 0.0 {
        1
    } else if o < 0.0 {
        -1
    } else {
        0
    }
}

/// Whether closed 2D segments `ab` and `cd` share a point.
fn segments_meet_2d(a: Coord<f64>, b: Coord<f64>, c: Coord<f64>, d: Coord<f64>) -> bool {
    let (d1, d2) = (sign2(a, b, c), sign2(a, b, d));
    let (d3, d4) = (sign2(c, d, a), sign2(c, d, b));
    if d1 * d2 < 0 && d3 * d4 < 0 {
        return true;
    }
    let within = |p: Coord<f64>, q: Coord<f64>, r: Coord<f64>| {
        r.x >= p.x.min(q.x) && r.x <= p.x.max(q.x) && r.y >= p.y.min(q.y) && r.y <= p.y.max(q.y)
    };
    (d1 == 0 && within(a, b, c))
        || (d2 == 0 && within(a, b, d))
        || (d3 == 0 && within(c, d, a))
        || (d4 == 0 && within(c, d, b))
}

/// Whether 2D point `p` lies in the closed triangle `t`.
fn in_triangle_2d(t: [Coord<f64>; 3], p: Coord<f64>) -> bool {
    let s = [sign2(t[0], t[1], p), sign2(t[1], t[2], p), sign2(t[2], t[0], p)];
    !(s.contains(&1) && s.contains(&-1))
}

/// Whether two coplanar closed triangles share a point.
fn coplanar_meet(p: [DVec3; 3], q: [DVec3; 3]) -> bool {
    let pts = project(p, &[p[0], p[1], p[2], q[0], q[1], q[2]]);
    let (a, b) = ([pts[0], pts[1], pts[2]], [pts[3], pts[4], pts[5]]);
    (0..3).any(|i| (0..3).any(|j| segments_meet_2d(a[i], a[(i + 1) % 3], b[j], b[(j + 1) % 3])))
        || in_triangle_2d(a, b[0])
        || in_triangle_2d(b, a[0])
}

/// Whether the closed segment `ab` meets the closed triangle `t` (exact).
fn segment_meets_triangle(a: DVec3, b: DVec3, t: [DVec3; 3]) -> bool {
    let (sa, sb) = (orient(t[0], t[1], t[2], a), orient(t[0], t[1], t[2], b));
    if sa * sb > 0 {
        return false;
    }
    if sa == 0 && sb == 0 {
        let pts = project(t, &[t[0], t[1], t[2], a, b]);
        let tri = [pts[0], pts[1], pts[2]];
        return in_triangle_2d(tri, pts[3])
            || (0..3).any(|i| segments_meet_2d(tri[i], tri[(i + 1) % 3], pts[3], pts[4]));
    }
    let s = [orient(a, b, t[0], t[1]), orient(a, b, t[1], t[2]), orient(a, b, t[2], t[0])];
    !(s.contains(&1) && s.contains(&-1))
}

/// Whether triangles `p` and `q` of a mesh, with vertex indices `pi` and `qi`, intersect other
/// than in what they share: no shared vertex — any common point; one shared vertex — the edge
/// opposite it in either triangle meets the other; a shared edge — folded flat onto each
/// other. Exact (Shewchuk's predicates). Open3D's check skips every pair sharing a vertex, so
/// this one is stricter.
fn triangles_intersect(p: [DVec3; 3], pi: [u32; 3], q: [DVec3; 3], qi: [u32; 3]) -> bool {
    let shared: Vec<(usize, usize)> =
        (0..3).flat_map(|i| (0..3).map(move |j| (i, j))).filter(|&(i, j)| pi[i] == qi[j]).collect();
    match shared.len() {
        0 => {
            let dq = [0, 1, 2].map(|i| orient(p[0], p[1], p[2], q[i]));
            let dp = [0, 1, 2].map(|i| orient(q[0], q[1], q[2], p[i]));
            if dq.iter().all(|&s| s == 1) || dq.iter().all(|&s| s == -1) {
                return false;
            }
            if dp.iter().all(|&s| s == 1) || dp.iter().all(|&s| s == -1) {
                return false;
            }
            if dp.iter().all(|&s| s == 0) {
                return coplanar_meet(p, q);
            }
            (0..3).any(|i| segment_meets_triangle(p[i], p[(i + 1) % 3], q))
                || (0..3).any(|i| segment_meets_triangle(q[i], q[(i + 1) % 3], p))
        }
        1 => {
            let (i, j) = shared[0];
            segment_meets_triangle(p[(i + 1) % 3], p[(i + 2) % 3], q)
                || segment_meets_triangle(q[(j + 1) % 3], q[(j + 2) % 3], p)
        }
        2 => {
            let (u, v) = (p[shared[0].0], p[shared[1].0]);
            let a = p[3 - shared[0].0 - shared[1].0];
            let b = q[3 - shared[0].1 - shared[1].1];
            if orient(u, v, a, b) != 0 {
                return false;
            }
            let pts = project([u, v, a], &[u, v, a, b]);
            sign2(pts[0], pts[1], pts[2]) == sign2(pts[0], pts[1], pts[3])
        }
        _ => true, // the same triangle twice
    }
}

/// The pairs of triangles of `mesh` that intersect (see [`triangles_intersect`]), found with
/// an R-tree of their bounding boxes.
pub fn self_intersecting_pairs(mesh: &Mesh) -> Vec<(usize, usize)> {
    let boxes: Vec<GeomWithData<Rectangle<[f64; 3]>, usize>> = (0..mesh.triangles.len())
        .map(|t| {
            let [a, b, c] = mesh.corners(t);
            let (lo, hi) = (a.min(b).min(c), a.max(b).max(c));
            GeomWithData::new(Rectangle::from_corners(lo.to_array(), hi.to_array()), t)
        })
        .collect();
    let tree = RTree::bulk_load(boxes);
    let mut pairs = Vec::new();
    for (a, b) in tree.intersection_candidates_with_other_tree(&tree) {
        let (s, t) = (a.data, b.data);
        if s < t
            && triangles_intersect(
                mesh.corners(s),
                mesh.triangles[s],
                mesh.corners(t),
                mesh.triangles[t],
            )
        {
            pairs.push((s, t));
        }
    }
    pairs
}

/// The faces whose normal is within `max_tilt_deg` of vertical and that lie between heights
/// `lo` and `hi` (all three corners): (their total area, the largest one's area), mm².
pub fn near_horizontal_area(mesh: &Mesh, lo: f64, hi: f64, max_tilt_deg: f64) -> (f64, f64) {
    let cos = max_tilt_deg.to_radians().cos();
    (0..mesh.triangles.len())
        .filter(|&t| mesh.corners(t).iter().all(|p| p.z >= lo && p.z <= hi))
        .filter_map(|t| {
            let n = mesh.scaled_normal(t);
            (n.length() > 0.0 && (n.z / n.length()).abs() >= cos).then(|| 0.5 * n.length())
        })
        .fold((0.0, 0.0), |(sum, big), a| (sum + a, f64::max(big, a)))
}

/// The front silhouette's top below `ceiling`: at each `x`, the highest point of the surface
/// that the vertical plane through `x` cuts below that height (`None` where it cuts nothing).
pub fn silhouette_top(mesh: &Mesh, xs: &[f64], ceiling: f64) -> Vec<Option<f64>> {
    let mut top: Vec<Option<f64>> = vec![None; xs.len()];
    for t in 0..mesh.triangles.len() {
        let c = mesh.corners(t);
        let (lo, hi) = c
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| (lo.min(p.x), hi.max(p.x)));
        for (k, &x) in xs.iter().enumerate() {
            if x < lo || x > hi {
                continue;
            }
            // The triangle's cut by the plane x: between the points where its edges cross it.
            let zs: Vec<f64> = (0..3)
                .map(|i| (c[i], c[(i + 1) % 3]))
                .filter(|(a, b)| (a.x - x) * (b.x - x) <= 0.0 && a.x != b.x)
                .map(|(a, b)| a.z + (b.z - a.z) * (x - a.x) / (b.x - a.x))
                .collect();
            let (z_lo, z_hi) = zs
                .iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &z| (lo.min(z), hi.max(z)));
            if z_lo <= ceiling {
                let z = z_hi.min(ceiling);
                if top[k].is_none_or(|best| z > best) {
                    top[k] = Some(z);
                }
            }
        }
    }
    top
}

/// The largest angle (degrees) between the normals of two triangles sharing an edge, over the
/// edges of `mesh` whose two triangles (their corners) `counts` accepts: a crease, seen in a
/// shaded picture as a line.
pub fn largest_crease(mesh: &Mesh, counts: impl Fn([DVec3; 3], [DVec3; 3]) -> bool) -> f64 {
    creases(mesh, |a, b, _| counts(a, b)).into_iter().fold(0.0, f64::max)
}

/// The angle (degrees) between the normals of the two triangles at each edge of `mesh` that
/// `counts` accepts (given both triangles' corners and the edge's two ends).
pub fn creases(
    mesh: &Mesh,
    counts: impl Fn([DVec3; 3], [DVec3; 3], [DVec3; 2]) -> bool,
) -> Vec<f64> {
    edge_creases(mesh, counts).into_iter().map(|(_, deg)| deg).collect()
}

/// As [`creases`], each angle with its edge's two ends.
pub fn edge_creases(
    mesh: &Mesh,
    counts: impl Fn([DVec3; 3], [DVec3; 3], [DVec3; 2]) -> bool,
) -> Vec<([DVec3; 2], f64)> {
    let mut faces_of_edge: HashMap<(u32, u32), Vec<usize>> = HashMap::new();
    for (t, tri) in mesh.triangles.iter().enumerate() {
        for k in 0..3 {
            let (a, b) = (tri[k], tri[(k + 1) % 3]);
            faces_of_edge.entry((a.min(b), a.max(b))).or_default().push(t);
        }
    }
    let normal = |t: usize| mesh.scaled_normal(t).normalize_or_zero();
    let ends = |(a, b): (u32, u32)| [a, b].map(|v| mesh.positions[v as usize]);
    faces_of_edge
        .iter()
        .filter_map(|(&edge, faces)| match faces[..] {
            [s, t] if counts(mesh.corners(s), mesh.corners(t), ends(edge)) => {
                Some((ends(edge), normal(s).dot(normal(t)).clamp(-1.0, 1.0).acos().to_degrees()))
            }
            _ => None,
        })
        .collect()
}

/// A vertex lies on a plate within this distance of its plane (mm).
const ON_PLATE_MM: f64 = 1e-3;

/// The rim of a flat arm plate: the longest boundary loop of the faces of a mesh lying in
/// one plane (see [`plate_rim`]).
#[derive(Debug, Clone, Copy)]
pub struct PlateRim {
    /// The rim's total turning (degrees): a convex curve turns 360 in all; each step of a
    /// staircase adds about 180.
    pub turning_deg: f64,
    /// The rim's vertex count.
    pub vertices: usize,
    /// The length of the rim's flat bottom (mm): its edges that lie level with its lowest
    /// vertex (within [`LEVEL_MM`]). A plate's rim is round at the bottom, but where the first
    /// ring to meet the plate does so with a long chord over a ring that does not reach it, the
    /// rim has a flat bottom that long over a tab leaning into the torso.
    pub flat_bottom_mm: f64,
}

/// Two rim vertices are level within this height difference (mm): the rings' heights are
/// written at 0.001 mm.
const LEVEL_MM: f64 = 0.01;

/// The rim of the flat region of `mesh` in the plane through `point` with unit normal
/// `normal`: the longest boundary loop of the faces whose corners all lie within
/// [`ON_PLATE_MM`] of the plane (`None` where no face lies on it).
pub fn plate_rim(mesh: &Mesh, point: DVec3, normal: DVec3) -> Option<PlateRim> {
    let on = |v: u32| (mesh.positions[v as usize] - point).dot(normal).abs() <= ON_PLATE_MM;
    let mut uses: HashMap<(u32, u32), usize> = HashMap::new();
    for tri in mesh.triangles.iter().filter(|tri| tri.iter().all(|&v| on(v))) {
        for k in 0..3 {
            let (a, b) = (tri[k], tri[(k + 1) % 3]);
            *uses.entry((a.min(b), a.max(b))).or_default() += 1;
        }
    }
    let mut next: HashMap<u32, Vec<u32>> = HashMap::new();
    for (&(a, b), _) in uses.iter().filter(|(_, n)| **n == 1) {
        next.entry(a).or_default().push(b);
        next.entry(b).or_default().push(a);
    }
    // Walk the boundary loops; keep the longest.
    let mut seen = std::collections::HashSet::new();
    let mut longest: Vec<u32> = Vec::new();
    for &start in next.keys() {
        if !seen.insert(start) {
            continue;
        }
        let (mut path, mut previous, mut at) = (vec![start], start, next[&start][0]);
        while at != start && seen.insert(at) {
            path.push(at);
            let step = next[&at].iter().copied().find(|&v| v != previous).unwrap_or(previous);
            (previous, at) = (at, step);
        }
        if path.len() > longest.len() {
            longest = path;
        }
    }
    if longest.len() < 3 {
        return None;
    }
    let (u, v) = normal.any_orthonormal_pair();
    let flat: Vec<glam::DVec2> = longest
        .iter()
        .map(|&k| {
            let p = mesh.positions[k as usize] - point;
            glam::DVec2::new(p.dot(u), p.dot(v))
        })
        .collect();
    let n = flat.len();
    let turning: f64 = (0..n)
        .map(|k| {
            let (a, b) = (flat[k] - flat[(k + n - 1) % n], flat[(k + 1) % n] - flat[k]);
            a.perp_dot(b).atan2(a.dot(b)).abs()
        })
        .sum();
    let at = |k: usize| mesh.positions[longest[k % n] as usize];
    let lowest = (0..n).map(|k| at(k).z).fold(f64::INFINITY, f64::min);
    let level = |p: DVec3| p.z - lowest <= LEVEL_MM;
    let flat_bottom_mm = (0..n)
        .filter(|&k| level(at(k)) && level(at(k + 1)))
        .map(|k| at(k).distance(at(k + 1)))
        .sum();
    Some(PlateRim { turning_deg: turning.to_degrees(), vertices: n, flat_bottom_mm })
}
