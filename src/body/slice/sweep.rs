//! Cutting a mesh by many horizontal planes at once.
//!
//! Each vertex counts the planes at or below it, and a triangle crosses the planes between its
//! corners' counts, so the work is proportional to the number of crossings, not triangles ×
//! planes. A triangle crossing plane `h` contributes one segment, from the point on its edge
//! that runs down through `h` to the point on its edge that runs up; for an outward-oriented
//! surface that makes outer loops counter-clockwise seen from above.

use super::{Contour, Section};
use crate::body::mesh::Mesh;
use glam::{DVec2, DVec3};
use rayon::prelude::*;
use rustc_hash::FxHashMap;

/// One triangle's piece of one plane: from `start` on edge `from` to the point on edge `to`.
/// That end point is the next segment's start (computed once, by the triangle it starts);
/// only an open chain's last end is computed again ([`crossing_of`]).
#[derive(Debug, Clone, Copy)]
struct Segment {
    from: u64,
    to: u64,
    start: DVec2,
}

/// Key of the undirected edge between vertices `a` and `b`.
fn edge_key(a: u32, b: u32) -> u64 {
    (u64::from(a.min(b)) << 32) | u64::from(a.max(b))
}

/// Where the edge between vertices `a` and `b` meets height `h`. Computed from the lower
/// vertex index, so both triangles sharing the edge get the same point.
fn crossing(mesh: &Mesh, a: u32, b: u32, h: f64) -> DVec2 {
    let (i, j) = (a.min(b) as usize, a.max(b) as usize);
    let (p, q): (DVec3, DVec3) = (mesh.positions[i], mesh.positions[j]);
    let t = (h - p.z) / (q.z - p.z);
    let t = if t.is_finite() { t.clamp(0.0, 1.0) } else { 0.0 };
    (p + (q - p) * t).truncate()
}

/// Where the edge with key `key` ([`edge_key`]) meets height `h`.
fn crossing_of(mesh: &Mesh, key: u64, h: f64) -> DVec2 {
    crossing(mesh, (key >> 32) as u32, key as u32, h)
}

/// The segment triangle `tri` leaves on the plane at `h`, the `plane`th lowest (it must cross
/// it); `below[v]` counts the planes at or below vertex `v`, so `v` is at or above `h` when
/// that count exceeds `plane` (a smaller table than the positions to look up).
fn segment(mesh: &Mesh, below: &[u32], plane: usize, tri: [u32; 3], h: f64) -> Segment {
    let above = tri.map(|v| below[v as usize] as usize > plane);
    let (mut down, mut up) = ((0, 0), (0, 0));
    for k in 0..3 {
        let (a, b) = (tri[k], tri[(k + 1) % 3]);
        match (above[k], above[(k + 1) % 3]) {
            (true, false) => down = (a, b),
            (false, true) => up = (a, b),
            _ => {}
        }
    }
    Segment {
        from: edge_key(down.0, down.1),
        to: edge_key(up.0, up.1),
        start: crossing(mesh, down.0, down.1, h),
    }
}

/// Cross-sections of `mesh` at each of `heights` (any order; returned in the same order). A
/// height that is not a finite number crosses nothing: its section is empty.
///
/// ```
/// use dressform::body::mesh::Mesh;
/// use dressform::body::slice::sections;
/// use glam::DVec3;
///
/// // A closed cube, 100 mm on a side, standing on the floor.
/// let corners = (0..8)
///     .map(|i| DVec3::new((i & 1) as f64, (i >> 1 & 1) as f64, (i >> 2) as f64) * 100.0)
///     .collect();
/// let faces = [[0, 2, 1], [1, 2, 3], [4, 5, 6], [5, 7, 6], [0, 1, 4], [1, 5, 4],
///              [2, 6, 3], [3, 6, 7], [0, 4, 2], [2, 4, 6], [1, 3, 5], [3, 7, 5]];
/// let cube = Mesh::new(corners, faces.to_vec());
///
/// let cut = sections(&cube, &[50.0, 150.0]);
/// assert_eq!(cut[0].loops.len(), 1); // one loop around the cube at 50 mm
/// assert!((cut[0].loops[0].perimeter() - 400.0).abs() < 1e-9);
/// assert!(cut[1].loops.is_empty()); // nothing above the cube
/// ```
pub fn sections(mesh: &Mesh, heights: &[f64]) -> Vec<Section> {
    let mut order: Vec<usize> = (0..heights.len()).filter(|&i| heights[i].is_finite()).collect();
    order.sort_by(|&a, &b| heights[a].total_cmp(&heights[b]));
    let planes = Planes::new(order.iter().map(|&i| heights[i]).collect());

    // A triangle crosses planes zmin < h <= zmax (a vertex on a plane counts as above it):
    // those from the fewest to the most planes at or below one of its vertices. So each
    // vertex is looked up once, and most triangles are dropped after comparing three counts.
    let below: Vec<u32> =
        mesh.positions.par_iter().map(|p| planes.at_or_below(p.z) as u32).collect();
    let n = planes.sorted.len();
    let crossings = Crossings::new(mesh, &below, &planes.sorted);
    let by_plane: Vec<Section> = (0..n)
        .into_par_iter()
        .map(|k| {
            let h = planes.sorted[k];
            chain(&crossings.of(k), h, |key| crossing_of(mesh, key, h))
        })
        .collect();
    let mut out: Vec<Section> = heights
        .iter()
        .map(|&height| Section { height, loops: Vec::new(), bridged_gaps: 0 })
        .collect();
    for (section, &i) in by_plane.into_iter().zip(&order) {
        out[i] = section;
    }
    out
}

/// Triangles per block of [`Crossings`]: enough blocks for every core on a scan, few enough
/// that a plane's list is a handful of slices.
const CROSSINGS_BLOCK: usize = 1 << 15;

/// Each plane's segments, in the order of their triangles: each block of [`CROSSINGS_BLOCK`]
/// triangles cuts its triangles by every plane they cross and sorts the segments by plane
/// (a counting sort; blocks in parallel), and a plane's segments are its slice of each block,
/// blocks in order. A block's triangles, the `below` counts of their corners and their
/// corners' positions are read while in cache (a scan's vertices lie near their triangles'
/// order), where cutting plane by plane read them scattered over the whole mesh.
struct Crossings {
    blocks: Vec<CrossingBlock>,
}

/// One block's segments by plane: those of plane `k` are `segments[offsets[k]..offsets[k + 1]]`.
struct CrossingBlock {
    offsets: Vec<u32>,
    segments: Vec<Segment>,
}

impl Crossings {
    /// The segments of the triangles of `mesh` on the planes at `heights` (sorted), whose
    /// vertices have `below[v]` planes at or below them: a triangle crosses the planes from
    /// its lowest vertex's count up to (not including) its highest's.
    fn new(mesh: &Mesh, below: &[u32], heights: &[f64]) -> Crossings {
        let planes = heights.len();
        let blocks = mesh
            .triangles
            .par_chunks(CROSSINGS_BLOCK)
            .map(|block| {
                let crossed: Vec<(u32, u32, [u32; 3])> = (block.iter())
                    .filter_map(|&tri| {
                        let c = tri.map(|v| below[v as usize]);
                        let (first, end) = (c[0].min(c[1]).min(c[2]), c[0].max(c[1]).max(c[2]));
                        (first < end).then_some((first, end, tri))
                    })
                    .collect();
                let mut offsets = vec![0u32; planes + 1];
                for &(first, end, _) in &crossed {
                    for k in first..end {
                        offsets[k as usize + 1] += 1;
                    }
                }
                for k in 0..planes {
                    offsets[k + 1] += offsets[k];
                }
                let mut fill = offsets.clone();
                let none = Segment { from: 0, to: 0, start: DVec2::ZERO };
                let mut segments = vec![none; offsets[planes] as usize];
                for &(first, end, tri) in &crossed {
                    for k in first as usize..end as usize {
                        segments[fill[k] as usize] = segment(mesh, below, k, tri, heights[k]);
                        fill[k] += 1;
                    }
                }
                CrossingBlock { offsets, segments }
            })
            .collect();
        Crossings { blocks }
    }

    /// The segments on plane `k`, in the order of their triangles.
    fn of(&self, k: usize) -> Vec<Segment> {
        let count = |b: &CrossingBlock| (b.offsets[k + 1] - b.offsets[k]) as usize;
        let mut segments = Vec::with_capacity(self.blocks.iter().map(count).sum());
        for b in &self.blocks {
            segments.extend_from_slice(&b.segments[b.offsets[k] as usize..][..count(b)]);
        }
        segments
    }
}

/// Sorted, finite plane heights, bucketed so that counting the planes at or below a height
/// takes a table lookup and a few comparisons with the planes near it instead of a search.
struct Planes {
    sorted: Vec<f64>,
    lowest: f64,
    /// Buckets per unit of height; 0 when the planes span no range a bucket can divide (one
    /// plane, all at one height, or a span too wide or too narrow for f64), and then the
    /// search runs over all planes.
    scale: f64,
    /// For a height in bucket `b` (entry `b`, the top edge's bucket included; the last entry:
    /// a height rounded past it), the planes it may lie among: those of its bucket, widened by
    /// one bucket on each side against rounding.
    near: Vec<Near>,
}

/// How many planes a [`Near`] compares without a search: up to 16,384 planes a bucket is a
/// quarter of their mean spacing, so its widened range holds one plane or none, and more only
/// where planes crowd together.
const NEAR: usize = 3;

/// The planes a height in one bucket may lie among: all planes before `from` lie at or below
/// it, all from `to` on above it.
#[derive(Clone, Copy)]
struct Near {
    from: usize,
    to: usize,
    /// The heights of planes `from..to`, then infinity, when there are at most [`NEAR`]: the
    /// count at or below a height is then branch-free.
    heights: Option<[f64; NEAR]>,
}

impl Planes {
    fn new(sorted: Vec<f64>) -> Planes {
        let (lowest, highest) = match (sorted.first(), sorted.last()) {
            (Some(&lo), Some(&hi)) => (lo, hi),
            _ => (0.0, 0.0),
        };
        let buckets = 4 * sorted.len().min(1 << 14);
        let scale = buckets as f64 / (highest - lowest);
        let scale = if highest > lowest && scale.is_finite() { scale } else { 0.0 };
        // `first[b]`: the planes at or below the lower edge of bucket `b`.
        let first: Vec<usize> = (0..=buckets)
            .map(|b| sorted.partition_point(|&h| (h - lowest) * scale <= b as f64))
            .collect();
        let near = (0..=buckets + 1)
            .map(|b| {
                let (from, to) =
                    (first[b.saturating_sub(1).min(buckets)], first[(b + 2).min(buckets)]);
                let heights = (to - from <= NEAR).then(|| {
                    let mut heights = [f64::INFINITY; NEAR];
                    heights[..to - from].copy_from_slice(&sorted[from..to]);
                    heights
                });
                Near { from, to, heights }
            })
            .collect();
        Planes { sorted, lowest, scale, near }
    }

    /// How many planes lie at or below `z` (none below a NaN).
    fn at_or_below(&self, z: f64) -> usize {
        let n = self.sorted.len();
        if n == 0 || z.is_nan() || z < self.lowest {
            return 0;
        }
        if z >= self.sorted[n - 1] {
            return n;
        }
        if self.scale == 0.0 {
            return self.sorted.partition_point(|&h| h <= z);
        }
        let b = ((z - self.lowest) * self.scale) as usize;
        let near = &self.near[b.min(self.near.len() - 1)];
        near.from
            + match &near.heights {
                Some(heights) => heights.iter().map(|&h| usize::from(h <= z)).sum(),
                None => self.sorted[near.from..near.to].partition_point(|&h| h <= z),
            }
    }
}

/// No segment.
const NONE: u32 = u32::MAX;

/// For each segment, the one that starts on the edge where it ends (`NONE` if there is
/// none); when several start on one edge (a non-manifold edge), the first of them.
fn successors(segments: &[Segment]) -> Vec<u32> {
    let mut starting: FxHashMap<u64, u32> =
        FxHashMap::with_capacity_and_hasher(segments.len(), Default::default());
    for (i, s) in segments.iter().enumerate().rev() {
        starting.insert(s.from, i as u32);
    }
    segments.iter().map(|s| starting.get(&s.to).copied().unwrap_or(NONE)).collect()
}

/// Chains one plane's segments into loops, closing open chains by pairing their loose ends;
/// `end(to)` is where a segment ends on its edge `to`.
fn chain(segments: &[Segment], height: f64, end: impl Fn(u64) -> DVec2) -> Section {
    let next = successors(segments);
    let mut is_target = vec![false; segments.len()];
    for &j in &next {
        if j != NONE {
            is_target[j as usize] = true;
        }
    }
    let mut used = vec![false; segments.len()];
    let walk = |first: usize, used: &mut Vec<bool>| -> (Vec<DVec2>, bool) {
        let mut points = Vec::new();
        let mut at = first;
        loop {
            used[at] = true;
            points.push(segments[at].start);
            match next[at] {
                j if j as usize == first => return (points, true),
                j if j != NONE && !used[j as usize] => at = j as usize,
                _ => {
                    points.push(end(segments[at].to)); // an open chain keeps its last point
                    return (points, false);
                }
            }
        }
    };
    let mut closed = Vec::new();
    let mut open = Vec::new();
    // Open chains first, from their heads, so that no chain is entered in the middle.
    for first in (0..segments.len()).filter(|&i| !is_target[i]) {
        if !used[first] {
            open.push(walk(first, &mut used).0);
        }
    }
    for first in 0..segments.len() {
        if !used[first] {
            let (points, is_closed) = walk(first, &mut used);
            if is_closed { closed.push(points) } else { open.push(points) }
        }
    }
    let bridged_gaps = open.len();
    closed.extend(close_open_chains(open));
    let mut loops: Vec<(f64, Contour)> = closed
        .into_iter()
        .filter(|p| p.len() >= 3)
        .map(|points| {
            let c = Contour { points };
            (c.signed_area().abs(), c)
        })
        .collect();
    loops.sort_by(|a, b| b.0.total_cmp(&a.0));
    Section { height, loops: loops.into_iter().map(|(_, c)| c).collect(), bridged_gaps }
}

/// How many of the nearest chain starts each open chain's end may be bridged to (besides its
/// own start): a plane crosses a few holes, so a handful is plenty.
const BRIDGE_CANDIDATES: usize = 8;

/// Joins open chains into loops by the shortest bridges first: of all (chain end, chain
/// start) pairs, its own start included, the closest pair is joined, then the closest of the
/// rest, and so on; each join bridges one gap of the scan ([`bridge`]), and the joins close
/// into loops. Taking the pairs in order of length makes the result independent of the
/// order the chains were found in, so that nearby planes through the same hole close the same
/// way (an arm and the torso seen through an armpit hole are joined at every level where the
/// gap between them is shorter than the hole, never at one level and not at the next).
fn close_open_chains(open: Vec<Vec<DVec2>>) -> Vec<Vec<DVec2>> {
    let n = open.len();
    // Each end's nearest starts (its own always among them): memory stays linear in the
    // number of chains on a mesh shredded into many (a fuzzed or broken file).
    let mut pairs: Vec<(f64, usize, usize)> = Vec::with_capacity(n * (BRIDGE_CANDIDATES + 1));
    let mut near: Vec<(f64, usize)> = Vec::with_capacity(n);
    for (i, chain) in open.iter().enumerate() {
        let end = chain[chain.len() - 1];
        near.clear();
        near.extend(open.iter().enumerate().map(|(j, c)| (end.distance_squared(c[0]), j)));
        if near.len() > BRIDGE_CANDIDATES {
            near.select_nth_unstable_by(BRIDGE_CANDIDATES, |a, b| a.0.total_cmp(&b.0));
            near.truncate(BRIDGE_CANDIDATES);
        }
        if !near.iter().any(|&(_, j)| j == i) {
            near.push((end.distance_squared(chain[0]), i));
        }
        pairs.extend(near.iter().map(|&(d, j)| (d, i, j)));
    }
    pairs.sort_by(|a, b| a.0.total_cmp(&b.0).then((a.1, a.2).cmp(&(b.1, b.2))));
    let (mut next, mut entered) = (vec![usize::MAX; n], vec![false; n]);
    for (_, i, j) in pairs {
        if next[i] == usize::MAX && !entered[j] {
            next[i] = j;
            entered[j] = true;
        }
    }
    // Ends whose candidates were all taken: the starts left over, in order.
    let mut free = (0..n).filter(|&j| !entered[j]);
    for at in next.iter_mut().filter(|at| **at == usize::MAX) {
        *at = free.next().expect("as many starts left as ends");
    }
    let mut taken = vec![false; n];
    let mut loops = Vec::new();
    for first in 0..n {
        let mut points = Vec::new();
        let mut at = first;
        while !taken[at] {
            taken[at] = true;
            points.extend_from_slice(&open[at]);
            points.extend(bridge(&open[at], &open[next[at]]));
            at = next[at];
        }
        if !points.is_empty() {
            loops.push(points);
        }
    }
    loops
}

/// Bridged gaps get a point at least this often (mm): a body scanner's mesh resolution.
const BRIDGE_STEP_MM: f64 = 5.0;
/// How far along a chain its direction at an end is taken (mm): over a few of a scan's
/// edges, so that its noise (about 1 mm) does not turn it.
const END_SPAN_MM: f64 = 15.0;

/// The points strictly between chain `from`'s end and chain `to`'s start that bridge the gap:
/// a cubic Hermite curve leaving `from` and entering `to` in the directions they run there
/// (tangents as long as the gap, close to a circular arc), so that a hole in a curved side is
/// bridged round the curve, not by the chord inside it (with chords across a scanner's holes
/// under the arms, the mannequins of 20 slightly posed MakeHuman bodies had chests -12.8 to
/// +1.7 mm off the true body's; with the curve, -4.9 to +1.7). Only a convex arc is bridged
/// so (both ends turned to the left of the gap, as an outer loop, counter-clockwise, turns
/// round the body; at most a quarter turn each): a concave gap (the crotch's hole, between
/// the thighs) keeps its chord, which is what a tape takes there anyway and what cannot cross
/// the loop. No points where the gap is under [`BRIDGE_STEP_MM`].
fn bridge(from: &[DVec2], to: &[DVec2]) -> Vec<DVec2> {
    let (p0, p1) = (from[from.len() - 1], to[0]);
    let gap = p1 - p0;
    let length = gap.length();
    if length <= BRIDGE_STEP_MM {
        return Vec::new();
    }
    let (Some(out), Some(into)) = (heading(from.iter().rev()), heading(to.iter()).map(|h| -h))
    else {
        return Vec::new();
    };
    let along = gap / length;
    let convex = out.perp_dot(along) >= 0.0 && along.perp_dot(into) >= 0.0;
    if !convex || out.dot(along) <= 0.0 || into.dot(along) <= 0.0 {
        return Vec::new();
    }
    let steps = (length / BRIDGE_STEP_MM).ceil() as usize;
    let (m0, m1) = (out * length, into * length);
    (1..steps)
        .map(|k| {
            let t = k as f64 / steps as f64;
            let (t2, t3) = (t * t, t * t * t);
            p0 * (2.0 * t3 - 3.0 * t2 + 1.0)
                + m0 * (t3 - 2.0 * t2 + t)
                + p1 * (-2.0 * t3 + 3.0 * t2)
                + m1 * (t3 - t2)
        })
        .collect()
}

/// The unit direction out of a chain at its end `points[0]` (`points` running from that end
/// inwards), `None` for a chain of one point. A chord's direction is the curve's halfway
/// along it, so on a curve it lags the end's; the chords over the first and second halves of
/// [`END_SPAN_MM`] (or of the chain, if shorter) are extrapolated to the end.
fn heading<'a>(points: impl Iterator<Item = &'a DVec2>) -> Option<DVec2> {
    let mut points = points.peekable();
    let end = **points.peek()?;
    let along: Vec<DVec2> = points.copied().take_while(|p| p.distance(end) < END_SPAN_MM).collect();
    let far = *along.last()?;
    let mid = along[along.len() / 2];
    let (near, rest) = ((end - mid).try_normalize(), (mid - far).try_normalize());
    match (near, rest) {
        (Some(a), Some(b)) => (1.5 * a - 0.5 * b).try_normalize(),
        _ => (end - far).try_normalize(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    /// A closed vertical prism over an n-gon of radius r, from z = 0 to z = 10, outward.
    fn prism(n: usize, r: f64) -> Mesh {
        let mut p = Vec::new();
        for z in [0.0, 10.0] {
            for i in 0..n {
                let a = 2.0 * PI * i as f64 / n as f64;
                p.push(DVec3::new(r * a.cos(), r * a.sin(), z));
            }
        }
        p.push(DVec3::new(0.0, 0.0, 0.0));
        p.push(DVec3::new(0.0, 0.0, 10.0));
        let n32 = n as u32;
        let mut t = Vec::new();
        for i in 0..n32 {
            let j = (i + 1) % n32;
            t.push([i, j, n32 + j]);
            t.push([i, n32 + j, n32 + i]);
            t.push([2 * n32, j, i]);
            t.push([2 * n32 + 1, n32 + i, n32 + j]);
        }
        Mesh::new(p, t)
    }

    #[test]
    fn prism_sections_are_ccw_polygons() {
        let mesh = prism(64, 50.0);
        assert!(mesh.signed_volume() > 0.0);
        let s = sections(&mesh, &[5.0, 2.5, 7.5]);
        assert_eq!(s.len(), 3);
        assert_eq!(s[1].height, 2.5);
        for sec in &s {
            assert_eq!(sec.loops.len(), 1);
            assert_eq!(sec.bridged_gaps, 0);
            let c = &sec.loops[0];
            assert_eq!(c.points.len(), 128, "a point on every side and every quad diagonal");
            assert!(c.signed_area() > 0.0, "counter-clockwise from above");
            let expected = 64.0 * 2.0 * 50.0 * (PI / 64.0).sin();
            assert!((c.perimeter() - expected).abs() < 1e-9);
        }
    }

    #[test]
    fn planes_through_vertices_still_give_closed_loops() {
        let mesh = prism(16, 10.0);
        for h in [0.0, 10.0] {
            let s = &sections(&mesh, &[h])[0];
            assert!(s.loops.iter().all(|l| l.points.len() >= 3));
            assert_eq!(s.bridged_gaps, 0);
        }
    }

    #[test]
    fn heights_that_are_no_numbers_or_far_apart_leave_the_others_exact() {
        let mesh = prism(64, 50.0);
        let heights = [2.5, f64::NAN, 7.5, f64::INFINITY, f64::NEG_INFINITY, 1e308, -1e308, 5.0];
        let s = sections(&mesh, &heights);
        assert_eq!(s.len(), heights.len());
        for (k, sec) in s.iter().enumerate() {
            let inside = (0.0..=10.0).contains(&heights[k]);
            assert_eq!(sec.loops.len(), usize::from(inside), "height {}", heights[k]);
            if inside {
                assert_eq!(sec.loops[0].points.len(), 128, "height {}", heights[k]);
            }
        }
        // A span too narrow to divide into buckets (subnormal numbers).
        let s = sections(&mesh, &[5e-310, 6e-310, 7e-310]);
        assert!(s.iter().all(|sec| sec.loops.len() == 1 && sec.loops[0].points.len() == 128));
    }

    #[test]
    fn planes_at_or_below_a_height_are_counted_exactly_where_they_crowd() {
        // Twelve planes within a bucket's width, others spread out, one repeated: every
        // height, on a plane or between, counts as a search over all planes counts.
        let mut sorted: Vec<f64> = (0..12).map(|i| 50.0 + 0.01 * i as f64).collect();
        sorted.extend([0.0, 10.0, 10.0, 33.3, 80.0, 100.0]);
        sorted.sort_by(f64::total_cmp);
        let planes = Planes::new(sorted.clone());
        let mut heights: Vec<f64> = (-10..=1100).map(|i| 0.1 * i as f64).collect();
        heights.extend(sorted.iter().flat_map(|&h| [h, h.next_down(), h.next_up()]));
        for z in heights {
            let searched = sorted.partition_point(|&h| h <= z);
            assert_eq!(planes.at_or_below(z), searched, "at z = {z}");
        }
        assert_eq!(planes.at_or_below(f64::NAN), 0);
    }

    #[test]
    fn planes_outside_give_empty_sections() {
        let s = sections(&prism(8, 1.0), &[-1.0, 11.0]);
        assert!(s.iter().all(|s| s.loops.is_empty()));
    }

    #[test]
    fn holes_are_bridged_and_reported() {
        let mut mesh = prism(32, 20.0);
        // Remove two side quads: a hole crossing the plane at z = 5.
        mesh.triangles.drain(0..8);
        let s = &sections(&mesh, &[5.0])[0];
        assert_eq!(s.loops.len(), 1);
        assert_eq!(s.bridged_gaps, 1);
        // The gap is bridged round the prism's curve, not by the chord across the two missing
        // sides: the loop is as long as the whole polygon's to within a tenth of a millimetre
        // (the chord is 0.04 mm short of the sides, an arc of the circle 0.01 over).
        let side = 2.0 * 20.0 * (PI / 32.0).sin();
        let chord = 2.0 * 20.0 * (2.0 * PI / 32.0).sin();
        let perimeter = s.loops[0].perimeter();
        assert!((perimeter - 32.0 * side).abs() < 0.1, "{perimeter} for {}", 32.0 * side);
        assert!(perimeter > 30.0 * side + chord);
    }

    #[test]
    fn a_hole_in_a_curved_side_is_bridged_round_the_curve() {
        // A 100 mm radius (a torso's side under the arm) with eight sides missing: a 78 mm
        // hole, whose chord is 2.0 mm shorter than the sides it replaces.
        let mut mesh = prism(64, 100.0);
        mesh.triangles.drain(0..32);
        let s = &sections(&mesh, &[5.0])[0];
        let side = 2.0 * 100.0 * (PI / 64.0).sin();
        let chord = 2.0 * 100.0 * (8.0 * PI / 64.0).sin();
        assert!(8.0 * side - chord > 1.9);
        let perimeter = s.loops[0].perimeter();
        assert!((perimeter - 64.0 * side).abs() < 0.3, "{perimeter} for {}", 64.0 * side);
    }

    /// `prism(32, 20)` without the sides (and their cap wedges) `sides`, moved by `dx`.
    fn holed_prism(sides: &[usize], dx: f64) -> Mesh {
        let mesh = prism(32, 20.0);
        let kept = mesh.triangles.iter().enumerate().filter(|(t, _)| !sides.contains(&(t / 4)));
        let moved = mesh.positions.iter().map(|p| *p + DVec3::X * dx).collect();
        Mesh::new(moved, kept.map(|(_, t)| *t).collect())
    }

    #[test]
    fn chains_close_alike_whatever_order_they_are_found_in() {
        // `b` is nearly closed (a 1 mm gap); `a`'s end is 5 mm from `b`'s start and 6 mm from
        // its own. Joining `a` to `b` first would bridge 5 mm and then 7 mm instead of 1 and 6.
        let pts = |p: &[(f64, f64)]| p.iter().map(|&(x, y)| DVec2::new(x, y)).collect::<Vec<_>>();
        let a = pts(&[(0.0, 6.0), (-10.0, 6.0), (-10.0, -10.0), (0.0, -10.0), (0.0, 0.0)]);
        let b = pts(&[(5.0, 0.0), (15.0, 0.0), (15.0, 10.0), (5.0, 10.0), (5.0, 1.0)]);
        for open in [vec![a.clone(), b.clone()], vec![b, a]] {
            let mut lengths: Vec<usize> = close_open_chains(open).iter().map(Vec::len).collect();
            lengths.sort();
            assert_eq!(lengths, [5, 5]);
        }
    }

    #[test]
    fn a_loop_cut_by_two_holes_is_joined_back_into_one() {
        let mesh = holed_prism(&[0, 1, 16, 17], 0.0);
        let s = &sections(&mesh, &[5.0])[0];
        assert_eq!(s.loops.len(), 1);
        assert_eq!(s.bridged_gaps, 2);
        assert!((s.loops[0].signed_area().abs() - PI * 400.0).abs() < 0.15 * PI * 400.0);
    }
}
