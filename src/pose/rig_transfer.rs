//! Rig transfer (paper 3.1.2): the scan takes the fitted model's skeleton and skin weights, so
//! that it can be re-posed with linear blend skinning (eq. 3).
//!
//! Each scan vertex takes the weights of its closest fitted-model triangle, interpolated
//! barycentrically (the paper's rule). Where the scan is far from the model or the normals
//! disagree (armpits, crotch, holes, clothing), that triangle is not trusted: those vertices
//! are filled from their neighbours instead (harmonic inpainting: each takes the mean of its
//! neighbours, swept until it settles), the trusted ones held fixed.

use crate::body::mesh::Mesh;
use crate::pose::model_fit::params::vertex_normals;
use crate::pose::skinning::SkinWeights;
use glam::DVec3;
use kiddo::{ImmutableKdTree, SquaredEuclidean};
use rayon::prelude::*;

/// A scan vertex farther than this from the fitted model does not take its triangle's weights
/// (mm): well above the fit's residual and a scanner's noise (a few mm), well below a limb's
/// radius (~50 mm), about 2% of the body's height (the design notes: "a few %").
pub const TRUSTED_DISTANCE_MM: f64 = 30.0;

/// Nor does one whose normal is more than 30 degrees from the model's there (the design notes).
pub const TRUSTED_NORMAL_COS: f64 = 0.866;

/// The model vertices nearest to a scan vertex whose triangles are searched for the closest
/// one: the closest triangle touches one of them unless the model is badly stretched.
const CANDIDATE_VERTICES: std::num::NonZeroUsize = std::num::NonZeroUsize::new(3).unwrap();

/// Sweeps of the inpainting over the filled vertices (Gauss-Seidel: each sweep updates in place): a filled region is at most a
/// hole's or an armpit's width across, a few dozen scan edges.
const FILL_SWEEPS: usize = 60;

/// What the transfer did.
#[derive(Debug, Clone, PartialEq)]
pub struct RigTransfer {
    /// The scan's skin weights (at most [`crate::pose::body_model::skeleton::MAX_INFLUENCES`] bones
    /// per vertex, in multiples of [`crate::pose::body_model::skeleton::WEIGHT_QUANTUM`], summing
    /// to 1).
    pub weights: SkinWeights,
    /// How many scan vertices took their weights from the neighbours.
    pub filled: usize,
}

/// The closest point to `p` on triangle `abc`, as barycentric coordinates (Ericson, *Real-Time
/// Collision Detection*, 5.1.5). Written here: the crates that have it (parry3d-f64) bring a
/// second glam.
pub fn closest_on_triangle(p: DVec3, [a, b, c]: [DVec3; 3]) -> [f64; 3] {
    let (ab, ac, ap) = (b - a, c - a, p - a);
    let (d1, d2) = (ab.dot(ap), ac.dot(ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return [1.0, 0.0, 0.0];
    }
    let bp = p - b;
    let (d3, d4) = (ab.dot(bp), ac.dot(bp));
    if d3 >= 0.0 && d4 <= d3 {
        return [0.0, 1.0, 0.0];
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        let v = d1 / (d1 - d3);
        return [1.0 - v, v, 0.0];
    }
    let cp = p - c;
    let (d5, d6) = (ab.dot(cp), ac.dot(cp));
    if d6 >= 0.0 && d5 <= d6 {
        return [0.0, 0.0, 1.0];
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        let w = d2 / (d2 - d6);
        return [1.0 - w, 0.0, w];
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && d4 - d3 >= 0.0 && d5 - d6 >= 0.0 {
        let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return [0.0, 1.0 - w, w];
    }
    let denom = 1.0 / (va + vb + vc);
    let (v, w) = (vb * denom, vc * denom);
    [1.0 - v - w, v, w]
}

/// Transfers the skin weights of the fitted `model` mesh (posed vertices in the scan's frame,
/// `model_weights` over `bones` bones) to `scan`.
pub fn transfer(
    scan: &Mesh,
    model: &Mesh,
    model_weights: &SkinWeights,
    bones: usize,
) -> RigTransfer {
    let model_normals = vertex_normals(&model.positions, &model.triangles);
    let scan_normals = vertex_normals(&scan.positions, &scan.triangles);
    let mut around: Vec<Vec<u32>> = vec![Vec::new(); model.positions.len()];
    for (t, tri) in model.triangles.iter().enumerate() {
        tri.iter().for_each(|&v| around[v as usize].push(t as u32));
    }
    let coords: Vec<[f64; 3]> = model.positions.iter().map(|p| p.to_array()).collect();
    let tree: ImmutableKdTree<f64, 3> = ImmutableKdTree::new_from_slice(&coords);
    // Per scan vertex: the interpolated weights, and whether they are trusted.
    let nearest: Vec<(Vec<f64>, bool)> = scan
        .positions
        .par_iter()
        .zip(&scan_normals)
        .map_init(Vec::new, |seen: &mut Vec<u32>, (&p, &n)| {
            let mut best = (f64::INFINITY, 0usize, [1.0, 0.0, 0.0]);
            seen.clear();
            for hit in tree.nearest_n::<SquaredEuclidean>(&p.to_array(), CANDIDATE_VERTICES) {
                // A triangle around two candidates is measured once (the first time: a
                // repeat, no nearer, would not replace it).
                for &t in &around[hit.item as usize] {
                    if seen.contains(&t) {
                        continue;
                    }
                    seen.push(t);
                    let corners = model.corners(t as usize);
                    let bary = closest_on_triangle(p, corners);
                    let q = bary[0] * corners[0] + bary[1] * corners[1] + bary[2] * corners[2];
                    let d = q.distance_squared(p);
                    if d < best.0 {
                        best = (d, t as usize, bary);
                    }
                }
            }
            let (d2, t, bary) = best;
            let tri = model.triangles[t];
            let mut w = vec![0.0; bones];
            let mut normal = DVec3::ZERO;
            for (&v, &b) in tri.iter().zip(&bary) {
                model_weights.of(v as usize).for_each(|(bone, x)| w[bone] += b * x);
                normal += b * model_normals[v as usize];
            }
            let trusted = d2.sqrt() <= TRUSTED_DISTANCE_MM
                && normal.normalize_or_zero().dot(n) >= TRUSTED_NORMAL_COS;
            (w, trusted)
        })
        .collect();
    let (mut weights, trusted): (Vec<Vec<f64>>, Vec<bool>) = nearest.into_iter().unzip();
    let filled = inpaint(scan, &mut weights, &trusted);
    RigTransfer { weights: quantised(&weights), filled }
}

/// Fills the untrusted vertices' weights from their neighbours (see the module documentation);
/// returns how many were filled. A piece of the scan with no trusted vertex keeps its own
/// closest-triangle weights.
///
/// The sweeps run on a compact copy: only the filled vertices and their neighbours, only the
/// bones any of them weighs (a bone none of them weighs stays zero in every mean).
fn inpaint(scan: &Mesh, weights: &mut [Vec<f64>], trusted: &[bool]) -> usize {
    let neighbours = Neighbours::new(scan);
    let (order, round) = fill_order(&neighbours, trusted);
    if order.is_empty() {
        return 0;
    }
    // The vertices the means read, the filled ones first (slot i is order[i]).
    let mut slot = vec![u32::MAX; scan.positions.len()];
    let mut vertices = order.clone();
    order.iter().enumerate().for_each(|(i, &v)| slot[v] = i as u32);
    for &v in &order {
        for &u in neighbours.of(v) {
            if slot[u as usize] == u32::MAX {
                slot[u as usize] = vertices.len() as u32;
                vertices.push(u as usize);
            }
        }
    }
    let bones: Vec<usize> = (0..weights[order[0]].len())
        .filter(|&b| vertices.iter().any(|&v| weights[v][b] != 0.0))
        .collect();
    let width = bones.len();
    let mut local: Vec<f64> = vertices
        .iter()
        .flat_map(|&v| {
            let w = &weights[v];
            bones.iter().map(move |&b| w[b])
        })
        .collect();
    let mut mean = vec![0.0; width];
    let mut sweep = |local: &mut Vec<f64>, usable: &dyn Fn(usize, usize) -> bool| {
        for (i, &v) in order.iter().enumerate() {
            mean.fill(0.0);
            let mut count = 0.0;
            for &u in neighbours.of(v).iter().filter(|&&u| usable(v, u as usize)) {
                let at = slot[u as usize] as usize * width;
                mean.iter_mut().zip(&local[at..at + width]).for_each(|(a, b)| *a += b);
                count += 1.0;
            }
            // Every filled vertex has a neighbour filled in an earlier round or trusted.
            mean.iter_mut().for_each(|a| *a /= count);
            local[i * width..(i + 1) * width].copy_from_slice(&mean);
        }
    };
    // Breadth first from the trusted vertices: each filled one starts as the mean of the
    // neighbours reached in earlier rounds, so the sweeps begin close to the solution.
    sweep(&mut local, &|v, u| round[u] < round[v]);
    for _ in 0..FILL_SWEEPS {
        sweep(&mut local, &|_, _| true);
    }
    for (i, &v) in order.iter().enumerate() {
        bones.iter().enumerate().for_each(|(j, &b)| weights[v][b] = local[i * width + j]);
    }
    order.len()
}

/// The vertices the inpainting fills, in the order it fills them (breadth first from the
/// trusted vertices, round by round), and each vertex's round (0 for the trusted ones,
/// `usize::MAX` for those never reached).
fn fill_order(neighbours: &Neighbours, trusted: &[bool]) -> (Vec<usize>, Vec<usize>) {
    let n = trusted.len();
    let mut round: Vec<usize> = trusted.iter().map(|&t| if t { 0 } else { usize::MAX }).collect();
    let mut front: Vec<usize> = (0..n).filter(|&v| trusted[v]).collect();
    let mut order = Vec::new();
    let mut r = 0;
    while !front.is_empty() {
        r += 1;
        let mut next = Vec::new();
        for &v in &front {
            for &u in neighbours.of(v) {
                let u = u as usize;
                if round[u] == usize::MAX {
                    round[u] = r;
                    next.push(u);
                }
            }
        }
        order.extend_from_slice(&next);
        front = next;
    }
    (order, round)
}

/// Each vertex's neighbours along the triangles' edges, in triangle order (an edge two
/// triangles share listed twice), in one array: the means add them in this order.
struct Neighbours {
    /// Where each vertex's neighbours start in `list` (one more entry than vertices).
    offsets: Vec<usize>,
    /// The neighbours of every vertex, one after the other.
    list: Vec<u32>,
}

impl Neighbours {
    /// Each edge of each triangle both ways, in triangle order.
    fn edges(scan: &Mesh) -> impl Iterator<Item = (u32, u32)> + '_ {
        scan.triangles.iter().flat_map(|tri| {
            (0..3).flat_map(move |k| {
                let (a, b) = (tri[k], tri[(k + 1) % 3]);
                [(a, b), (b, a)]
            })
        })
    }

    /// The neighbours of `scan`'s vertices.
    fn new(scan: &Mesh) -> Self {
        let mut offsets = vec![0; scan.positions.len() + 1];
        Self::edges(scan).for_each(|(a, _)| offsets[a as usize + 1] += 1);
        for v in 0..scan.positions.len() {
            offsets[v + 1] += offsets[v];
        }
        let mut list = vec![0; offsets[scan.positions.len()]];
        let mut next = offsets.clone();
        for (a, b) in Self::edges(scan) {
            list[next[a as usize]] = b;
            next[a as usize] += 1;
        }
        Neighbours { offsets, list }
    }

    /// The neighbours of vertex `v`.
    fn of(&self, v: usize) -> &[u32] {
        &self.list[self.offsets[v]..self.offsets[v + 1]]
    }
}

/// Each vertex's strongest bones (at most `MAX_INFLUENCES`) as multiples of `WEIGHT_QUANTUM`
/// summing to exactly 1 (the rounding remainder on the strongest), as glTF wants them.
fn quantised(weights: &[Vec<f64>]) -> SkinWeights {
    use crate::pose::body_model::skeleton::{MAX_INFLUENCES, WEIGHT_QUANTUM};
    let steps = (1.0 / WEIGHT_QUANTUM) as i64;
    SkinWeights::normalised(
        weights
            .par_iter()
            .map(|w| {
                let mut order: Vec<usize> = (0..w.len()).filter(|&b| w[b] > 0.0).collect();
                order.sort_by(|&a, &b| w[b].total_cmp(&w[a]).then(a.cmp(&b)));
                order.truncate(MAX_INFLUENCES);
                let total: f64 = order.iter().map(|&b| w[b]).sum();
                let mut q: Vec<i64> =
                    order.iter().map(|&b| (w[b] / total * steps as f64).round() as i64).collect();
                let rest = steps - q.iter().sum::<i64>();
                if let Some(first) = q.first_mut() {
                    *first += rest;
                }
                order
                    .into_iter()
                    .zip(q)
                    .filter(|&(_, k)| k > 0)
                    .map(|(b, k)| (b, k as f64 * WEIGHT_QUANTUM))
                    .collect()
            })
            .collect(),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_closest_point_is_found_in_each_region_of_a_triangle() {
        let t = [DVec3::ZERO, DVec3::X, DVec3::Y];
        let at = |b: [f64; 3]| b[0] * t[0] + b[1] * t[1] + b[2] * t[2];
        let cases = [
            (DVec3::new(0.25, 0.25, 1.0), DVec3::new(0.25, 0.25, 0.0)),
            (DVec3::new(-1.0, -1.0, 0.0), DVec3::ZERO),
            (DVec3::new(0.5, -2.0, 0.3), DVec3::new(0.5, 0.0, 0.0)),
            (DVec3::new(1.0, 1.0, 0.0), DVec3::new(0.5, 0.5, 0.0)),
            (DVec3::new(3.0, -1.0, 0.0), DVec3::X),
        ];
        for (p, want) in cases {
            let got = at(closest_on_triangle(p, t));
            assert!(got.distance(want) < 1e-12, "{p}: {got} vs {want}");
        }
    }

    #[test]
    fn far_vertices_take_their_neighbours_weights() {
        // A strip of four squares; the model is the first square only, with bone 0 on x = 0
        // and bone 1 on x = 1. Scan vertices beyond x = 1 + 30 mm are filled from x = 1.
        let square = |x0: f64| [DVec3::new(x0, 0.0, 0.0), DVec3::new(x0, 1.0, 0.0)];
        let positions: Vec<DVec3> =
            (0..5).flat_map(|i| square(i as f64 * 20.0)).collect::<Vec<_>>();
        let triangles: Vec<[u32; 3]> = (0..4u32)
            .flat_map(|i| [[2 * i, 2 * i + 2, 2 * i + 3], [2 * i, 2 * i + 3, 2 * i + 1]])
            .collect();
        let scan = Mesh::new(positions.clone(), triangles);
        let model = Mesh::new(positions[..4].to_vec(), vec![[0, 2, 3], [0, 3, 1]]);
        let w = SkinWeights::normalised(vec![
            vec![(0, 1.0)],
            vec![(0, 1.0)],
            vec![(1, 1.0)],
            vec![(1, 1.0)],
        ]);
        let rig = transfer(&scan, &model, &w, 2);
        // x = 0, 20 on the model; x = 40 is 20 mm off (trusted); 60 and 80 are filled.
        assert_eq!(rig.filled, 4);
        for v in 0..scan.positions.len() {
            let on_1: f64 = rig.weights.of(v).filter(|&(b, _)| b == 1).map(|(_, x)| x).sum();
            let want = if v < 2 { 0.0 } else { 1.0 };
            assert!((on_1 - want).abs() < 1e-9, "vertex {v}: {on_1}");
        }
    }
}
