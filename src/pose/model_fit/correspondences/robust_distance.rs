//! How far the posed model lies from the scan, robustly, both ways ([`RobustDistance`]): the
//! measure that tells several starts apart ([`crate::pose::model_fit::arm_starts`]). The starts
//! turn one arm, so most of the model stands still between them: what the still part
//! contributes (its vertices' pairs to the scan, the nearest still vertex of each scan sample)
//! is found once, and each start searches only the moving part. The result is the same, bit
//! for bit, as searching the whole model each time (the sums keep their order; a scan sample's
//! nearest vertex is the nearer of the nearest still and the nearest moving one).

use super::{MIN_NORMAL_COS, ScanCloud};
use crate::body::mesh::reduce;
use crate::pose::model_fit::robust;
use glam::DVec3;
use kiddo::{ImmutableKdTree, SquaredEuclidean};
use rayon::prelude::*;
use std::num::NonZeroUsize;

/// The robust distance between the scan and poses of the model that move only the vertices
/// marked as moving (see the module documentation): the mean Geman-McClure cost
/// ([`robust::cost`] at scale `sigma`) of each model vertex to its nearest scan point and of
/// each sampled scan point to its nearest model vertex, a pair whose normals disagree (or
/// whose scan point lies on a hole's boundary) counted as unmatched, at the full `sigma^2`;
/// the two directions weigh alike. Unlike the quadratics of [`super::gather`], whose weights
/// vanish for pairs far apart (a limb far from the scan costs almost nothing there), this
/// charges every part of the model away from the scan, and every part of the scan the model
/// does not cover.
pub struct RobustDistance<'c> {
    cloud: &'c ScanCloud<'c>,
    sigma: f64,
    /// Per model vertex: whether its position or normal may differ between the poses.
    moving: Vec<bool>,
    /// The moving vertices.
    moving_list: Vec<usize>,
    /// What the still vertices contribute, from the first pose measured.
    still: Option<Still>,
}

/// What the still part of the model contributes, the same in every pose.
struct Still {
    /// Per model vertex: its pair's cost to the scan (zero for the moving ones).
    to_scan: Vec<f64>,
    /// Per scan sample: its nearest still vertex and their squared distance (`usize::MAX` and
    /// infinity when every vertex moves).
    nearest: Vec<(usize, f64)>,
}

impl<'c> RobustDistance<'c> {
    /// The distance to `cloud` at scale `sigma` (mm) of poses that differ only in the vertices
    /// `moving` marks (their positions or normals).
    pub fn new(cloud: &'c ScanCloud<'c>, sigma: f64, moving: Vec<bool>) -> Self {
        let moving_list = (0..moving.len()).filter(|&v| moving[v]).collect();
        RobustDistance { cloud, sigma, moving, moving_list, still: None }
    }

    /// The distance of the posed model (`vertices` with `normals`); the still vertices must
    /// stand where they stood in the first pose measured.
    pub fn of(&mut self, vertices: &[DVec3], normals: &[DVec3]) -> f64 {
        let (cloud, sigma) = (self.cloud, self.sigma);
        let scan = cloud.scan;
        let unmatched = sigma * sigma;
        let pair = |v: usize, s: usize| {
            let agree = normals[v].dot(scan.normals[s]) >= MIN_NORMAL_COS;
            if agree && !scan.on_hole_boundary[s] {
                robust::cost(vertices[v].distance_squared(scan.points[s]), sigma)
            } else {
                unmatched
            }
        };
        let to_scan_of = |v: usize| {
            let hit = cloud.tree.nearest_one::<SquaredEuclidean>(&vertices[v].to_array());
            pair(v, hit.item as usize)
        };
        let moving = &self.moving;
        let still = self.still.get_or_insert_with(|| Still {
            to_scan: (0..vertices.len())
                .into_par_iter()
                .map(|v| if moving[v] { 0.0 } else { to_scan_of(v) })
                .collect(),
            nearest: nearest_among(cloud, vertices, |v| !moving[v], |_| f64::INFINITY),
        });
        // The moving vertices' costs first, spread evenly over the threads (an arm's vertices
        // lie together in the model's order), then all summed in a fixed order
        // ([`reduce::sum`]): the arm starts compare these costs, and a rayon `sum` rounds
        // differently from run to run.
        let mut to_scan = still.to_scan.clone();
        let moved: Vec<(usize, f64)> =
            self.moving_list.par_iter().map(|&v| (v, to_scan_of(v))).collect();
        moved.into_iter().for_each(|(v, cost)| to_scan[v] = cost);
        let to_scan = reduce::sum(vertices.len(), |v| to_scan[v]);
        // Only a moving vertex nearer than the nearest still one matters: the search of the
        // moving part is bounded by it (most samples lie far from the arm, and end at once).
        let nearest = &still.nearest;
        let nearest_moving = nearest_among(cloud, vertices, |v| moving[v], |i| nearest[i].1);
        let to_model = reduce::sum(cloud.samples.len(), |i| {
            let (still_v, still_d2) = still.nearest[i];
            let (moving_v, moving_d2) = nearest_moving[i];
            let v = if moving_d2 < still_d2 { moving_v } else { still_v };
            pair(v, cloud.samples[i])
        });
        let (vertices, samples) = (vertices.len().max(1) as f64, cloud.samples.len().max(1) as f64);
        0.5 * (to_scan / vertices + to_model / samples)
    }
}

/// For each of `cloud`'s samples, its nearest among the `vertices` that `among` accepts, and
/// their squared distance, where that is less than `within(sample)` (the sample's index
/// among the samples), otherwise `usize::MAX` and infinity.
fn nearest_among(
    cloud: &ScanCloud,
    vertices: &[DVec3],
    among: impl Fn(usize) -> bool,
    within: impl Fn(usize) -> f64 + Sync,
) -> Vec<(usize, f64)> {
    let index: Vec<usize> = (0..vertices.len()).filter(|&v| among(v)).collect();
    if index.is_empty() {
        return vec![(usize::MAX, f64::INFINITY); cloud.samples.len()];
    }
    let coords: Vec<[f64; 3]> = index.iter().map(|&v| vertices[v].to_array()).collect();
    let tree: ImmutableKdTree<f64, 3> = ImmutableKdTree::new_from_slice(&coords);
    let points = cloud.scan.points;
    reduce::blocks(cloud.samples.len(), |range| {
        range
            .map(|i| {
                let point = points[cloud.samples[i]].to_array();
                let bound = within(i);
                let hit = if bound.is_finite() {
                    let one = NonZeroUsize::MIN;
                    tree.nearest_n_within::<SquaredEuclidean>(&point, bound, one, false).pop()
                } else {
                    Some(tree.nearest_one::<SquaredEuclidean>(&point))
                };
                match hit {
                    Some(hit) if hit.distance < bound => (index[hit.item as usize], hit.distance),
                    _ => (usize::MAX, f64::INFINITY),
                }
            })
            .collect::<Vec<_>>()
    })
    .concat()
}

#[cfg(test)]
mod tests {
    use super::super::{ScanCloud, ScanPoints};
    use super::*;

    /// `n` points spread over a sphere of `radius` (a Fibonacci spiral), each pushed out by a
    /// little of `wobble` so that no two distances tie.
    fn sphere(n: usize, radius: f64, wobble: f64) -> Vec<DVec3> {
        let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
        (0..n)
            .map(|i| {
                let z = 1.0 - 2.0 * (i as f64 + 0.5) / n as f64;
                let (r, a) = ((1.0 - z * z).sqrt(), golden * i as f64);
                DVec3::new(r * a.cos(), r * a.sin(), z)
                    * (radius + wobble * (i as f64 * 0.37).sin())
            })
            .collect()
    }

    /// The distance searched by brute force over the whole model: what [`RobustDistance`]
    /// must give, to the bit (the same pairs, summed in the same order).
    fn brute(cloud: &ScanCloud, sigma: f64, vertices: &[DVec3], normals: &[DVec3]) -> f64 {
        let scan = cloud.scan;
        let pair = |v: usize, s: usize| {
            let agree = normals[v].dot(scan.normals[s]) >= MIN_NORMAL_COS;
            if agree && !scan.on_hole_boundary[s] {
                robust::cost(vertices[v].distance_squared(scan.points[s]), sigma)
            } else {
                sigma * sigma
            }
        };
        let nearest = |p: DVec3, among: &[DVec3]| {
            (0..among.len()).min_by(|&a, &b| {
                p.distance_squared(among[a]).total_cmp(&p.distance_squared(among[b]))
            })
        };
        let to_scan = reduce::sum(vertices.len(), |v| {
            pair(v, nearest(vertices[v], scan.points).expect("a scan point"))
        });
        let to_model = reduce::sum(cloud.samples.len(), |i| {
            let s = cloud.samples[i];
            pair(nearest(scan.points[s], vertices).expect("a vertex"), s)
        });
        0.5 * (to_scan / vertices.len() as f64 + to_model / cloud.samples.len() as f64)
    }

    #[test]
    fn searching_the_moving_part_alone_gives_the_whole_search_to_the_bit() {
        let points = sphere(3000, 100.0, 2.0);
        let mut on_hole_boundary = vec![false; points.len()];
        on_hole_boundary[10..40].iter_mut().for_each(|b| *b = true);
        let normals = points.iter().map(|p| p.normalize()).collect();
        let scan = ScanPoints { points: &points, normals, on_hole_boundary };
        let cloud = ScanCloud::new(&scan, 3);
        let model = sphere(800, 104.0, 3.0);
        let moving: Vec<bool> = model.iter().map(|p| p.x > 40.0).collect();
        let sigma = 10.0;
        let mut distance = RobustDistance::new(&cloud, sigma, moving.clone());
        // The arm turned about the vertical axis, further each time: the still part stays.
        for angle in [0.0f64, 0.1, 0.3, 0.6] {
            let turn = glam::DQuat::from_rotation_z(angle);
            let posed: Vec<DVec3> = (0..model.len())
                .map(|v| if moving[v] { turn * model[v] } else { model[v] })
                .collect();
            let normals: Vec<DVec3> = posed.iter().map(|p| p.normalize()).collect();
            let found = distance.of(&posed, &normals);
            let expected = brute(&cloud, sigma, &posed, &normals);
            assert_eq!(
                found.to_bits(),
                expected.to_bits(),
                "at {angle} rad: {found} vs {expected}"
            );
        }
    }
}
