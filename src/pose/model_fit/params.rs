//! The fit's unknowns (eq. 4's `theta`, `beta` and the global translation), their layout in the
//! normal equations, and the posed model they give with everything the Jacobians need.

use crate::pose::body_model::BodyModel;
use crate::pose::skinning;
use glam::{DAffine3, DMat3, DQuat, DVec3};
use rayon::prelude::*;

/// The unknowns: a global translation (mm), one rotation vector per bone (the root's is the
/// global rotation; convention of [`crate::pose::skinning`]) and the shape coefficients.
#[derive(Debug, Clone, PartialEq)]
pub struct Params {
    /// Added after the rotations (mm).
    pub translation: DVec3,
    /// Per bone, its rotation vector relative to its parent (radians).
    pub theta: Vec<DVec3>,
    /// The shape coefficients (standard deviations).
    pub beta: Vec<f64>,
}

/// Where each unknown sits in the parameter vector: translation, then three per bone (a
/// world-frame rotation increment about the bone's posed joint), then beta.
#[derive(Debug, Clone, Copy)]
pub struct Layout {
    /// The number of bones.
    pub bones: usize,
    /// The number of shape coefficients.
    pub k: usize,
}

impl Layout {
    /// The number of parameters.
    pub fn size(&self) -> usize {
        3 + 3 * self.bones + self.k
    }
    /// The first index of bone `b`'s rotation increment.
    pub fn bone(&self, b: usize) -> usize {
        3 + 3 * b
    }
    /// The index of shape coefficient `k`.
    pub fn beta(&self, k: usize) -> usize {
        3 + 3 * self.bones + k
    }
}

/// What the fit needs of the model, computed once: its rest joints and their derivatives with
/// respect to beta (joints are linear in beta, eq. 1), and the bone hierarchy.
pub struct PreparedModel<'m> {
    /// The model.
    pub model: &'m BodyModel,
    /// The mean body's joints.
    pub joints0: Vec<DVec3>,
    /// `R d_k`: per component, per bone.
    pub joint_directions: Vec<Vec<DVec3>>,
    /// `descends[k][l]`: whether bone `l` is `k` or below it.
    pub descends: Vec<Vec<bool>>,
    /// The parameter layout.
    pub layout: Layout,
}

impl<'m> PreparedModel<'m> {
    /// Prepares `model` for fitting.
    pub fn new(model: &'m BodyModel) -> Self {
        let parents = &model.skeleton.parents;
        let n = parents.len();
        let mut descends = vec![vec![false; n]; n];
        for (k, row) in descends.iter_mut().enumerate() {
            for l in 0..n {
                row[l] = l == k || parents[l].is_some_and(|p| row[p]);
            }
        }
        PreparedModel {
            model,
            joints0: model.joints(&[]),
            joint_directions: model.joint_directions(),
            descends,
            layout: Layout { bones: n, k: model.k() },
        }
    }

    /// The mean model at rest, moved by `translation`.
    pub fn start(&self, translation: DVec3) -> Params {
        Params {
            translation,
            theta: vec![DVec3::ZERO; self.layout.bones],
            beta: vec![0.0; self.layout.k],
        }
    }

    /// The model posed by `params` (eq. 3), with its bone motions.
    pub fn pose(&self, params: &Params) -> Posed {
        let model = self.model;
        let rest = model.shape(&params.beta);
        let mut joints = self.joints0.clone();
        for (b, dj) in params.beta.iter().zip(&self.joint_directions) {
            joints.iter_mut().zip(dj).for_each(|(j, d)| *j += *b * *d);
        }
        let parents = &model.skeleton.parents;
        let g = skinning::bone_transforms(parents, &joints, &params.theta, params.translation);
        let vertices = skinning::skin(&rest, &model.weights, &g);
        let pivots: Vec<DVec3> = (0..g.len()).map(|l| g[l].transform_point3(joints[l])).collect();
        // dt_l / dbeta_k = sum over the chain m from the root to l of (A_parent(m) - A_m) R d_k[m]
        // (t_l = translation + sum_m (A_parent(m) - A_m) j_m; A the rotation parts).
        let mut joint_shift = vec![vec![DVec3::ZERO; self.layout.k]; g.len()];
        for l in 0..g.len() {
            let above = parents[l].map_or(DMat3::IDENTITY, |p| g[p].matrix3);
            let own = g[l].matrix3;
            let shift = (self.joint_directions.iter().enumerate())
                .map(|(k, dj)| {
                    let here = (above - own) * dj[l];
                    parents[l].map_or(here, |p| joint_shift[p][k] + here)
                })
                .collect();
            joint_shift[l] = shift;
        }
        Posed { rest, g, vertices, pivots, joint_shift }
    }

    /// The posed vertex's Jacobian: `(parameter index, d vertex / d parameter)` for every
    /// parameter that moves vertex `v`. A world-frame turn `dw` of bone `k` moves the vertex by
    /// `sum_l w_l dw x (x_l - p_k)` over its bones `l` at or below `k` (`x_l` the rest vertex
    /// moved by bone `l` alone, `p_k` bone `k`'s posed joint); beta moves the rest vertex by
    /// `d_k` and the joints by `R d_k`.
    pub fn jacobian(&self, posed: &Posed, v: usize, out: &mut Vec<(usize, DVec3)>) {
        out.clear();
        let layout = self.layout;
        out.extend([(0, DVec3::X), (1, DVec3::Y), (2, DVec3::Z)]);
        let bones: Vec<(usize, f64, DVec3)> = self
            .model
            .weights
            .of(v)
            .map(|(l, w)| (l, w, posed.g[l].transform_point3(posed.rest[v])))
            .collect();
        for k in 0..layout.bones {
            let mut arm = DVec3::ZERO;
            let mut moved = false;
            for &(l, w, x) in &bones {
                if self.descends[k][l] {
                    arm += w * (x - posed.pivots[k]);
                    moved = true;
                }
            }
            if moved {
                let at = layout.bone(k);
                out.extend([
                    (at, DVec3::X.cross(arm)),
                    (at + 1, DVec3::Y.cross(arm)),
                    (at + 2, DVec3::Z.cross(arm)),
                ]);
            }
        }
        for k in 0..layout.k {
            let d = self.model.components[k][v];
            let col: DVec3 = bones
                .iter()
                .map(|&(l, w, _)| w * (posed.g[l].matrix3 * d + posed.joint_shift[l][k]))
                .sum();
            out.push((layout.beta(k), col));
        }
    }
}

/// The model posed by some [`Params`].
pub struct Posed {
    /// The rest vertices of the shape (eq. 2).
    pub rest: Vec<DVec3>,
    /// Each bone's motion `G_l`.
    pub g: Vec<DAffine3>,
    /// The posed vertices (eq. 3).
    pub vertices: Vec<DVec3>,
    /// Each bone's posed joint `p_k = G_k(j_k)`.
    pub pivots: Vec<DVec3>,
    /// `d t_l / d beta_k` per bone, per component (see [`PreparedModel::pose`]).
    pub joint_shift: Vec<Vec<DVec3>>,
}

impl Params {
    /// Applies a parameter step (layout of [`Layout`]): translation and beta add; bone `k`'s
    /// world-frame turn `dw` becomes `R_k <- exp(A_parent^T dw) R_k` in its parent's frame.
    pub fn step(
        &self,
        layout: Layout,
        posed: &Posed,
        parents: &[Option<usize>],
        d: &[f64],
    ) -> Params {
        let mut next = self.clone();
        next.translation += DVec3::new(d[0], d[1], d[2]);
        for (b, theta) in next.theta.iter_mut().enumerate() {
            let at = layout.bone(b);
            let dw = DVec3::new(d[at], d[at + 1], d[at + 2]);
            if dw == DVec3::ZERO {
                continue;
            }
            let above: DMat3 = parents[b].map_or(DMat3::IDENTITY, |p| posed.g[p].matrix3);
            let local = above.transpose() * dw;
            *theta = (DQuat::from_scaled_axis(local) * DQuat::from_scaled_axis(*theta))
                .normalize()
                .to_scaled_axis();
        }
        for (k, b) in next.beta.iter_mut().enumerate() {
            *b += d[layout.beta(k)];
        }
        next
    }
}

/// Area-weighted vertex normals of a triangle mesh (unit length; zero for unused vertices).
pub fn vertex_normals(vertices: &[DVec3], triangles: &[[u32; 3]]) -> Vec<DVec3> {
    let mut n = vec![DVec3::ZERO; vertices.len()];
    for t in triangles {
        let [a, b, c] = t.map(|i| vertices[i as usize]);
        let face = (b - a).cross(c - a);
        for &i in t {
            n[i as usize] += face;
        }
    }
    n.par_iter_mut().for_each(|v| *v = v.normalize_or_zero());
    n
}
