//! Linear blend skinning (paper eq. 3): a posed vertex is its rest position moved by the
//! weighted blend of its bones' rigid motions, `D(theta, v_i) = sum_l w^l(v_i) G_l(theta) v_i`,
//! where `G_l` composes the rotations of bone `l` and its ancestors, each about its own joint.
//!
//! **Angle convention** (used by [`crate::pose::makehuman::Pose`] and the body model): bone `l`'s
//! rotation `theta_l` is a rotation vector (axis times angle in radians, right-hand rule) in the
//! axes of the rest pose's frame (canonical: X the subject's left, Y backwards, Z up), about the
//! bone's joint `j_l` in the rest pose, relative to its parent:
//! `G_l = G_parent(l) * T(j_l) * R(theta_l) * T(-j_l)`, and the root's `G` starts from a global
//! translation. Zero rotations leave every vertex where it is (the rest pose, MakeHuman's
//! A-pose). Example: with the arms of the A-pose pointing down and outwards, a positive angle
//! about +Y turns the left upper arm (`+X`) down towards the body, a negative one raises it.

use glam::{DAffine3, DMat3, DVec3};
use rayon::prelude::*;

/// Vertices handed to one parallel task when skinning (small meshes stay on one thread).
const VERTICES_PER_TASK: usize = 4096;

/// Per-vertex bone weights, compressed: vertex `v`'s bones and weights are
/// `bones[offsets[v]..offsets[v + 1]]` and the same range of `weights`.
#[derive(Debug, Clone, PartialEq)]
pub struct SkinWeights {
    offsets: Vec<u32>,
    bones: Vec<u32>,
    weights: Vec<f64>,
}

impl SkinWeights {
    /// From each vertex's `(bone, weight)` list, scaled to sum 1 (a vertex with no weight
    /// keeps none and stays put). Pairs are kept in the order given.
    pub fn normalised(per_vertex: Vec<Vec<(usize, f64)>>) -> Self {
        let mut s = SkinWeights { offsets: vec![0], bones: Vec::new(), weights: Vec::new() };
        for list in per_vertex {
            let total: f64 = list.iter().map(|&(_, w)| w).sum();
            for (bone, w) in list {
                if total > 0.0 && w > 0.0 {
                    s.bones.push(bone as u32);
                    s.weights.push(w / total);
                }
            }
            s.offsets.push(s.bones.len() as u32);
        }
        s
    }

    /// The number of vertices.
    pub fn len(&self) -> usize {
        self.offsets.len() - 1
    }

    /// Whether there are no vertices.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Vertex `v`'s `(bone, weight)` pairs.
    pub fn of(&self, v: usize) -> impl Iterator<Item = (usize, f64)> + '_ {
        let range = self.offsets[v] as usize..self.offsets[v + 1] as usize;
        self.bones[range.clone()]
            .iter()
            .map(|&b| b as usize)
            .zip(self.weights[range].iter().copied())
    }
}

/// The rotation matrix of a rotation vector (axis times angle, radians).
pub fn rotation(theta: DVec3) -> DMat3 {
    DMat3::from_quat(glam::DQuat::from_scaled_axis(theta))
}

/// Each bone's rigid motion `G_l` for rotations `theta` (one rotation vector per bone) about
/// rest-pose joints `joints`, then `translation`; `parents[l]` must come before `l`.
pub fn bone_transforms(
    parents: &[Option<usize>],
    joints: &[DVec3],
    theta: &[DVec3],
    translation: DVec3,
) -> Vec<DAffine3> {
    let mut g: Vec<DAffine3> = Vec::with_capacity(parents.len());
    for (l, parent) in parents.iter().enumerate() {
        let local = DAffine3::from_translation(joints[l])
            * DAffine3::from_mat3(rotation(theta[l]))
            * DAffine3::from_translation(-joints[l]);
        let above = match parent {
            Some(p) => g[*p],
            None => DAffine3::from_translation(translation),
        };
        g.push(above * local);
    }
    g
}

/// Linear blend skinning of `vertices` (eq. 3): each vertex moved by the blend of its bones'
/// motions. Computed as `v + sum_l w_l (G_l v - v)` (the same for weights summing to 1), so that
/// bones at rest leave a vertex exactly where it was.
pub fn skin(vertices: &[DVec3], weights: &SkinWeights, transforms: &[DAffine3]) -> Vec<DVec3> {
    vertices
        .par_iter()
        .with_min_len(VERTICES_PER_TASK)
        .enumerate()
        .map(|(v, &p)| {
            p + weights
                .of(v)
                .map(|(b, w)| w * (transforms[b].transform_point3(p) - p))
                .sum::<DVec3>()
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_child_turns_with_its_parent_about_the_parents_joint() {
        // A chain along +X: bone 0 at the origin, bone 1 at x = 1; a vertex at x = 2 on bone 1.
        let parents = [None, Some(0)];
        let joints = [DVec3::ZERO, DVec3::X];
        let quarter = std::f64::consts::FRAC_PI_2;
        let g = bone_transforms(&parents, &joints, &[DVec3::Z * quarter, DVec3::ZERO], DVec3::ZERO);
        let w = SkinWeights::normalised(vec![vec![(1, 1.0)]]);
        let p = skin(&[DVec3::new(2.0, 0.0, 0.0)], &w, &g)[0];
        assert!(p.distance(DVec3::new(0.0, 2.0, 0.0)) < 1e-12, "{p}");
        // Bone 1 alone turns about its own joint (1, 0, 0).
        let g = bone_transforms(&parents, &joints, &[DVec3::ZERO, DVec3::Z * quarter], DVec3::ZERO);
        let p = skin(&[DVec3::new(2.0, 0.0, 0.0)], &w, &g)[0];
        assert!(p.distance(DVec3::new(1.0, 1.0, 0.0)) < 1e-12, "{p}");
    }

    #[test]
    fn weights_are_normalised_and_blend_linearly() {
        let w = SkinWeights::normalised(vec![vec![(0, 3.0), (1, 1.0)], vec![]]);
        assert_eq!(w.of(0).collect::<Vec<_>>(), vec![(0, 0.75), (1, 0.25)]);
        assert_eq!(w.of(1).count(), 0);
        let g = [DAffine3::IDENTITY, DAffine3::from_translation(DVec3::X * 4.0)];
        assert_eq!(skin(&[DVec3::ZERO, DVec3::Y], &w, &g), vec![DVec3::X, DVec3::Y]);
    }
}
