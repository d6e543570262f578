//! Closest-point pairs both ways between the posed model and the scan (eq. 4's data term):
//! model vertices to their nearest scan points, and sampled scan points to their nearest model
//! vertices, each pair rejected when the two normals disagree or the scan point lies on a hole's
//! boundary (Turk & Levoy 1994: a model vertex over a hole finds its nearest scan point on the
//! rim, and would be dragged there), each weighted robustly ([`super::robust`]). Nearest
//! neighbours by `kiddo` k-d trees.

pub mod robust_distance;

use super::params::vertex_normals;
use super::robust;
use crate::body::mesh::{Mesh, topology};
use glam::{DMat3, DVec3};
use kiddo::{ImmutableKdTree, SquaredEuclidean};
use rayon::prelude::*;

/// Pairs whose normals are more than 60 degrees apart are rejected (a front surface matched to
/// a back one, an arm to the torso beside it): the usual threshold of robust ICP.
pub const MIN_NORMAL_COS: f64 = 0.5;

/// The weight of point-to-point beside point-to-plane distances: "a little point-to-point"
/// keeps points from sliding along flat surfaces without slowing convergence (1/10 is the
/// common choice in registration).
pub const POINT_TO_POINT: f64 = 0.1;

/// The scan as the fit sees it: points, unit outward normals, and which points lie on the
/// boundary of a hole.
pub struct ScanPoints<'a> {
    /// The points (mm, canonical frame).
    pub points: &'a [DVec3],
    /// Their unit outward normals.
    pub normals: Vec<DVec3>,
    /// Per point, whether it lies on a hole's boundary (all `false` for a bare point cloud).
    pub on_hole_boundary: Vec<bool>,
}

impl<'a> ScanPoints<'a> {
    /// A scan mesh's vertices, with its vertex normals and its boundary loops.
    pub fn of_mesh(mesh: &'a Mesh) -> Self {
        let mut on_hole_boundary = vec![false; mesh.positions.len()];
        for v in topology(mesh).boundary_loops.iter().flatten() {
            on_hole_boundary[*v as usize] = true;
        }
        ScanPoints {
            points: &mesh.positions,
            normals: vertex_normals(&mesh.positions, &mesh.triangles),
            on_hole_boundary,
        }
    }

    /// A point cloud with unit `normals` (no holes known).
    pub fn of_cloud(points: &'a [DVec3], normals: Vec<DVec3>) -> Self {
        ScanPoints { points, on_hole_boundary: vec![false; points.len()], normals }
    }
}

/// The scan indexed for pairing: a k-d tree over its points, and its samples.
pub struct ScanCloud<'a> {
    /// The scan.
    pub scan: &'a ScanPoints<'a>,
    tree: ImmutableKdTree<f64, 3>,
    /// The scan points used for scan-to-model pairs (none on a hole's boundary).
    samples: Vec<usize>,
}

impl<'a> ScanCloud<'a> {
    /// Indexes `scan` and picks every `stride`-th point off the holes' boundaries as a sample
    /// for scan-to-model pairs.
    pub fn new(scan: &'a ScanPoints<'a>, stride: usize) -> Self {
        let coords: Vec<[f64; 3]> = scan.points.iter().map(|p| p.to_array()).collect();
        let tree = ImmutableKdTree::new_from_slice(&coords);
        let samples =
            (0..scan.points.len()).step_by(stride.max(1)).filter(|&s| !scan.on_hole_boundary[s]);
        ScanCloud { scan, tree, samples: samples.collect() }
    }
}

/// The data term for the current correspondences, gathered per model vertex: the cost of
/// vertex `v` at position `x` is `x^T A x - 2 c.x + e` (the weighted sum of its pairs'
/// point-to-plane and point-to-point squared distances), divided by the pair count.
pub struct Quadratics {
    /// `(vertex, A, c, e)` for each vertex with pairs.
    pub terms: Vec<(usize, DMat3, DVec3, f64)>,
    /// The pairs found in each direction (model to scan, scan to model) before weighting.
    pub pairs: [usize; 2],
    /// The root mean square of the point-to-plane distances of the pairs, per direction (mm).
    pub rms_mm: [f64; 2],
}

impl Quadratics {
    /// The data cost of posed vertices `x`.
    pub fn cost(&self, x: &[DVec3]) -> f64 {
        self.terms.iter().map(|(v, a, c, e)| x[*v].dot(*a * x[*v]) - 2.0 * c.dot(x[*v]) + e).sum()
    }
}

/// One pair: model vertex, scan point, the normal of its plane, its robust weight.
struct Pair {
    vertex: usize,
    target: DVec3,
    normal: DVec3,
    weight: f64,
    plane_mm: f64,
}

/// The pairs both ways between the posed model (`vertices` with `normals`) and the scan, robust
/// weights at scale `sigma` (mm), gathered per vertex.
pub fn gather(cloud: &ScanCloud, vertices: &[DVec3], normals: &[DVec3], sigma: f64) -> Quadratics {
    let scan = cloud.scan;
    let weigh = |vertex: usize, target: DVec3, normal: DVec3| {
        let d = vertices[vertex] - target;
        let plane = normal.dot(d);
        let r2 = plane * plane + POINT_TO_POINT * d.length_squared();
        Pair {
            vertex,
            target,
            normal,
            weight: robust::geman_mcclure(r2.sqrt(), sigma),
            plane_mm: plane,
        }
    };
    let to_scan: Vec<Pair> = (0..vertices.len())
        .into_par_iter()
        .filter_map(|v| {
            let hit = cloud.tree.nearest_one::<SquaredEuclidean>(&vertices[v].to_array());
            let s = hit.item as usize;
            let agree = normals[v].dot(scan.normals[s]) >= MIN_NORMAL_COS;
            (agree && !scan.on_hole_boundary[s]).then(|| weigh(v, scan.points[s], scan.normals[s]))
        })
        .collect();
    let coords: Vec<[f64; 3]> = vertices.iter().map(|p| p.to_array()).collect();
    let model_tree: ImmutableKdTree<f64, 3> = ImmutableKdTree::new_from_slice(&coords);
    let to_model: Vec<Pair> = cloud
        .samples
        .par_iter()
        .filter_map(|&s| {
            let hit = model_tree.nearest_one::<SquaredEuclidean>(&scan.points[s].to_array());
            let v = hit.item as usize;
            (normals[v].dot(scan.normals[s]) >= MIN_NORMAL_COS)
                .then(|| weigh(v, scan.points[s], normals[v]))
        })
        .collect();
    let rms = |p: &[Pair]| {
        (p.iter().map(|p| p.plane_mm * p.plane_mm).sum::<f64>() / p.len().max(1) as f64).sqrt()
    };
    let mut per_vertex: Vec<Option<(DMat3, DVec3, f64)>> = vec![None; vertices.len()];
    for (set, count) in [(&to_scan, to_scan.len()), (&to_model, to_model.len())] {
        // Each direction counts as the mean over its pairs, the two equally.
        let share = 0.5 / count.max(1) as f64;
        for p in set.iter() {
            let m = (DMat3::from_cols(
                p.normal * p.normal.x,
                p.normal * p.normal.y,
                p.normal * p.normal.z,
            ) + DMat3::IDENTITY * POINT_TO_POINT)
                * (p.weight * share);
            let ms = m * p.target;
            let entry = per_vertex[p.vertex].get_or_insert((DMat3::ZERO, DVec3::ZERO, 0.0));
            entry.0 += m;
            entry.1 += ms;
            entry.2 += p.target.dot(ms);
        }
    }
    let terms = per_vertex
        .into_iter()
        .enumerate()
        .filter_map(|(v, t)| t.map(|(a, c, e)| (v, a, c, e)))
        .collect();
    Quadratics {
        terms,
        pairs: [to_scan.len(), to_model.len()],
        rms_mm: [rms(&to_scan), rms(&to_model)],
    }
}
