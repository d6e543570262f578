//! The statistical body model (paper 3.1.1): a template mesh with its mirror map, a 21-bone
//! skeleton with exactly symmetric skin weights, joints by mean value coordinates (eq. 1), a
//! PCA shape space (eq. 2, k = 15) and linear blend skinning (eq. 3):
//!
//! `M(theta, beta) = LBS(V(beta), J(beta), theta)`, with `V(beta) = mean + sum_k beta_k d_k`
//! (`d_k = sigma_k u_k`: beta in units of standard deviations) and `J(beta) = R V(beta)`
//! (`R` the MVC regressor), so the joints are linear in beta: `J(beta) = J_0 + sum_k beta_k R
//! d_k`, derivatives constant ([`BodyModel::joint_directions`]).
//!
//! Everything is in the canonical frame (mm, Z up, +X left, facing -Y); the file is glTF
//! ([`file`]). The rest pose is MakeHuman's A-pose; angles follow [`crate::pose::skinning`].

mod build;
pub mod file;
pub mod mvc;
pub mod pca;
pub mod population;
pub mod skeleton;
pub mod template;

pub use build::{BuildError, BuildOptions, BuildProgress, from_makehuman, from_meshes};
pub use skeleton::Skeleton;

use crate::body::mesh::Mesh;
use crate::pose::skinning::{self, SkinWeights};
use glam::DVec3;
use rayon::prelude::*;

/// The largest |beta| a sampled body takes, standard deviations: beyond 5 sigma a normal
/// population has fewer than 1 body in 1.7 million. Within it the built-in model's bodies are
/// 1.1 to 2.3 m tall (every component at +5 or -5), people that `dressform info` reads.
pub const MAX_BETA: f64 = 5.0;

/// Vertices handed to one parallel task when evaluating the model.
const VERTICES_PER_TASK: usize = 2048;

/// How a model was made (kept in the file).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Provenance {
    /// `"makehuman"` or `"meshes"`.
    pub source: String,
    /// How many bodies went into the PCA.
    pub bodies: usize,
    /// The sampling seed (MakeHuman bodies).
    pub seed: Option<u64>,
    /// The population's total variance (mm², over the whole body vector).
    pub total_variance_mm2: f64,
}

/// The body model. Build it with [`from_makehuman`] or [`from_meshes`], read it with
/// [`file::read`], or take the built-in one ([`BodyModel::builtin`]).
#[derive(Debug, Clone, PartialEq)]
pub struct BodyModel {
    /// The template's triangles (counter-clockwise from outside; closed, genus 0).
    pub triangles: Vec<[u32; 3]>,
    /// Each vertex's mirror partner about x = 0.
    pub mirror: Vec<u32>,
    /// The mean body (mm).
    pub mean: Vec<DVec3>,
    /// The shape directions `d_k = sigma_k u_k` (mm per unit beta), per component per vertex.
    pub components: Vec<Vec<DVec3>>,
    /// Each component's standard deviation `sigma_k` (mm, over the whole body vector).
    pub sigmas: Vec<f64>,
    /// The fraction of the population's variance each component explains.
    pub explained: Vec<f64>,
    /// The skeleton.
    pub skeleton: Skeleton,
    /// Skin weights (at most 4 bones per vertex, exactly mirror-symmetric, summing to 1).
    pub weights: SkinWeights,
    /// The MVC regressor (eq. 1): per joint (= bone), one weight per vertex.
    pub regressor: Vec<Vec<f64>>,
    /// How it was made.
    pub provenance: Provenance,
}

impl BodyModel {
    /// The number of shape components `k`.
    pub fn k(&self) -> usize {
        self.components.len()
    }

    /// The body of shape `beta` in the rest pose (eq. 2); missing coefficients are 0.
    pub fn shape(&self, beta: &[f64]) -> Vec<DVec3> {
        let beta = &beta[..beta.len().min(self.k())];
        self.mean
            .par_iter()
            .with_min_len(VERTICES_PER_TASK)
            .enumerate()
            .map(|(v, &m)| {
                m + beta.iter().zip(&self.components).map(|(b, d)| *b * d[v]).sum::<DVec3>()
            })
            .collect()
    }

    /// The joints of any body in the template's topology (eq. 1): `j_n = sum_i m^n_i v_i`.
    pub fn regress_joints(&self, vertices: &[DVec3]) -> Vec<DVec3> {
        self.regressor
            .par_iter()
            .map(|m| m.iter().zip(vertices).map(|(w, v)| *w * *v).sum())
            .collect()
    }

    /// The rest joints of shape `beta`: `J_0 + sum_k beta_k (R d_k)`.
    pub fn joints(&self, beta: &[f64]) -> Vec<DVec3> {
        let mut j = self.regress_joints(&self.mean);
        for (b, dj) in beta.iter().zip(self.joint_directions()) {
            j.iter_mut().zip(dj).for_each(|(p, d)| *p += *b * d);
        }
        j
    }

    /// How the joints move per unit of each shape coefficient (`R d_k`): the constant
    /// derivative of the joints with respect to beta.
    pub fn joint_directions(&self) -> Vec<Vec<DVec3>> {
        self.components.iter().map(|d| self.regress_joints(d)).collect()
    }

    /// `M(theta, beta)`: the body of shape `beta` posed by `theta` (one rotation vector per
    /// bone, see [`crate::pose::skinning`]) and moved by `translation` (mm).
    pub fn posed(&self, beta: &[f64], theta: &[DVec3], translation: DVec3) -> Vec<DVec3> {
        let rest = self.shape(beta);
        let joints = self.regress_joints(&rest);
        let g = skinning::bone_transforms(&self.skeleton.parents, &joints, theta, translation);
        skinning::skin(&rest, &self.weights, &g)
    }

    /// The shape coefficients of `body` (in the template's topology, rest pose) by least
    /// squares, `beta_k = <body - mean, d_k> / sigma_k^2` (the directions are orthogonal), and
    /// the body they give.
    pub fn project(&self, body: &[DVec3]) -> (Vec<f64>, Vec<DVec3>) {
        let offset: Vec<DVec3> = body.iter().zip(&self.mean).map(|(p, m)| *p - *m).collect();
        let beta: Vec<f64> = self
            .components
            .iter()
            .zip(&self.sigmas)
            .map(|(d, s)| d.iter().zip(&offset).map(|(a, b)| a.dot(*b)).sum::<f64>() / (s * s))
            .collect();
        let back = self.shape(&beta);
        (beta, back)
    }

    /// A vertex list as a mesh with the template's triangles.
    pub fn mesh(&self, vertices: Vec<DVec3>) -> Mesh {
        Mesh::new(vertices, self.triangles.clone())
    }
}

impl BodyModel {
    /// The built-in model file: built by `dressform model build` from the MakeHuman assets
    /// with the default options (see `src/pose/body_model/README.md`).
    pub const BUILTIN_GLB: &'static [u8] = include_bytes!("default_model.glb");

    /// The built-in model (a test reads it, so it cannot fail at run time).
    pub fn builtin() -> BodyModel {
        file::from_bytes(Self::BUILTIN_GLB)
            .unwrap_or_else(|e| panic!("the built-in body model: {e}"))
    }
}
