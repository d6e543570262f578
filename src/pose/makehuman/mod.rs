//! The CC0 MakeHuman assets (`../shared/makehuman`, see its README): the base mesh "hm08",
//! sparse morph targets, the default 163-bone rig and its skin weights, and posing a body with
//! that rig by linear blend skinning.
//!
//! Everything is converted on load to the canonical body frame (mm, Z up, +X the subject's
//! left, facing -Y): MakeHuman's decimetres, Y up, facing +Z become `(x, y, z) -> 100 (x, -z,
//! y)` ([`to_canonical`]), a rotation plus a scale, so targets, joints and weights keep their
//! meaning. The origin stays MakeHuman's (near the hips), not the floor.
//!
//! ```no_run
//! use dressform::pose::makehuman::{MakeHuman, Pose};
//! use glam::DVec3;
//! let mh = MakeHuman::load(std::path::Path::new("../shared/makehuman"))?;
//! let body = mh.shaped(&[("measure/measure-waist-circ-incr", 0.6)])?;
//! let pose = Pose::rest().rotate("upperarm01.L", DVec3::new(0.0, -0.5, 0.0));
//! let skin = mh.base.skin(&mh.pose(&body, &pose)?);
//! # Ok::<(), dressform::pose::makehuman::MakeHumanError>(())
//! ```

mod base_mesh;
mod pose;
mod rig;
mod target;
mod weights;

pub use base_mesh::{BaseMesh, Group};
pub use pose::Pose;
pub use rig::{Bone, Rig};
pub use target::Target;

use crate::pose::skinning::SkinWeights;
use glam::DVec3;
use std::path::{Path, PathBuf};

/// Millimetres per MakeHuman unit (the assets are in decimetres).
pub const MM_PER_UNIT: f64 = 100.0;

/// A point or offset from MakeHuman's frame (dm, Y up, facing +Z) into the canonical one (mm,
/// Z up, facing -Y).
pub fn to_canonical(x: f64, y: f64, z: f64) -> DVec3 {
    DVec3::new(x, -z, y) * MM_PER_UNIT
}

/// A problem with one of the asset files: which file, and what is wrong with it.
#[derive(Debug, thiserror::Error)]
#[error("{}: {problem}", file.display())]
pub struct MakeHumanError {
    /// The file at fault.
    pub file: PathBuf,
    /// What is wrong (one line).
    pub problem: String,
}

impl MakeHumanError {
    fn new(file: &Path, problem: impl Into<String>) -> Self {
        MakeHumanError { file: file.to_path_buf(), problem: problem.into() }
    }
}

/// Reads a whole asset file as text.
fn read_text(file: &Path) -> Result<String, MakeHumanError> {
    std::fs::read_to_string(file)
        .map_err(|e| MakeHumanError::new(file, format!("cannot read: {e}")))
}

/// The loaded assets: base mesh, rig and skin weights. Targets are read on demand.
#[derive(Debug, Clone)]
pub struct MakeHuman {
    /// The asset folder.
    pub dir: PathBuf,
    /// `base.obj`: every vertex (skin, helpers, joint cubes) and the groups' faces.
    pub base: BaseMesh,
    /// `rigs/default.mhskel`: 163 bones, parents before children.
    pub rig: Rig,
    /// `rigs/default_weights.mhw`: per vertex of the full list, its bones (indices into
    /// `rig.bones`) and weights, normalised to sum 1.
    pub weights: SkinWeights,
}

impl MakeHuman {
    /// Loads `base.obj`, `rigs/default.mhskel` and `rigs/default_weights.mhw` from `dir`.
    pub fn load(dir: &Path) -> Result<Self, MakeHumanError> {
        let base = BaseMesh::load(&dir.join("base.obj"))?;
        let rig = Rig::load(&dir.join("rigs/default.mhskel"), base.vertices.len())?;
        let weights =
            weights::load(&dir.join("rigs/default_weights.mhw"), &rig, base.vertices.len())?;
        Ok(MakeHuman { dir: dir.to_path_buf(), base, rig, weights })
    }

    /// Reads the target `targets/<name>.target` (`name` as in `"measure/measure-waist-circ-incr"`).
    pub fn target(&self, name: &str) -> Result<Target, MakeHumanError> {
        let file = self.dir.join("targets").join(format!("{name}.target"));
        Target::load(&file, self.base.vertices.len())
    }

    /// The full vertex list of the base mesh with the named targets applied with their weights:
    /// `base + sum_i w_i target_i` (MakeHuman's rule).
    pub fn shaped(&self, targets: &[(&str, f64)]) -> Result<Vec<DVec3>, MakeHumanError> {
        let mut vertices = self.base.vertices.clone();
        for &(name, weight) in targets {
            self.target(name)?.apply(&mut vertices, weight);
        }
        Ok(vertices)
    }

    /// Poses a full vertex list (the base mesh, shaped or not) with the 163-bone rig: the
    /// joints are recomputed from `vertices` (means of their listed vertices), then every vertex
    /// is moved by linear blend skinning. See [`Pose`] for the angle convention. An unknown bone
    /// name is an error naming the rig file.
    pub fn pose(&self, vertices: &[DVec3], pose: &Pose) -> Result<Vec<DVec3>, MakeHumanError> {
        pose::apply(self, vertices, pose)
    }
}
