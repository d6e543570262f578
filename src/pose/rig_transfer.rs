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

/// Jacobi sweeps of the inpainting over the filled vertices: a filled region is at most a
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
        .map(|(&p, &n)| {
            let mut best = (f64::INFINITY, 0usize, [1.0, 0.0, 0.0]);
            for hit in tree.nearest_n::<SquaredEuclidean>(&p.to_array(), CANDIDATE_VERTICES) {
                for &t in &around[hit.item as usize] {
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
fn inpaint(scan: &Mesh, weights: &mut [Vec<f64>], trusted: &[bool]) -> usize {
    let n = scan.positions.len();
    let mut neighbours: Vec<Vec<u32>> = vec![Vec::new(); n];
    for tri in &scan.triangles {
        for k in 0..3 {
            let (a, b) = (tri[k], tri[(k + 1) % 3]);
            neighbours[a as usize].push(b);
            neighbours[b as usize].push(a);
        }
    }
    // Breadth first from the trusted vertices: each untrusted one starts as the mean of the
    // neighbours reached in earlier rounds, so the sweeps begin close to the solution.
    let mut round: Vec<usize> = trusted.iter().map(|&t| if t { 0 } else { usize::MAX }).collect();
    let mut front: Vec<usize> = (0..n).filter(|&v| trusted[v]).collect();
    let mut order = Vec::new();
    let mut mean = vec![0.0; weights.first().map_or(0, Vec::len)];
    let mut r = 0;
    while !front.is_empty() {
        r += 1;
        let mut next = Vec::new();
        for &v in &front {
            for &u in &neighbours[v] {
                let u = u as usize;
                if round[u] == usize::MAX {
                    round[u] = r;
                    next.push(u);
                }
            }
        }
        for &u in &next {
            if mean_of(&neighbours[u], weights, |x| round[x] < r, &mut mean) {
                weights[u].copy_from_slice(&mean);
            }
        }
        order.extend_from_slice(&next);
        front = next;
    }
    for _ in 0..FILL_SWEEPS {
        for &v in &order {
            if mean_of(&neighbours[v], weights, |_| true, &mut mean) {
                weights[v].copy_from_slice(&mean);
            }
        }
    }
    order.len()
}

/// The mean weights of the `neighbours` that `usable` accepts, into `mean` (as long as a
/// vertex's weights); whether there was any.
fn mean_of(
    neighbours: &[u32],
    weights: &[Vec<f64>],
    usable: impl Fn(usize) -> bool,
    mean: &mut [f64],
) -> bool {
    mean.fill(0.0);
    let mut count = 0.0;
    for &u in neighbours.iter().filter(|&&u| usable(u as usize)) {
        mean.iter_mut().zip(&weights[u as usize]).for_each(|(a, b)| *a += b);
        count += 1.0;
    }
    if count > 0.0 {
        mean.iter_mut().for_each(|a| *a /= count);
    }
    count > 0.0
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
