//! Building a model: from MakeHuman (sampled bodies, the paper's PCA over them) or from
//! registered meshes in a template's topology (the paper's path, e.g. a body database).

#[cfg(doc)]
use super::file;
use super::{BodyModel, Provenance, mvc, pca, population, skeleton, template};
use crate::body::mesh::Mesh;
use crate::pose::makehuman::MakeHuman;
use glam::DVec3;
use rayon::prelude::*;

/// What to build.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BuildOptions {
    /// Bodies sampled from MakeHuman.
    pub bodies: usize,
    /// Shape components kept (`k`).
    pub components: usize,
    /// The sampling seed.
    pub seed: u64,
}

impl Default for BuildOptions {
    /// The built-in model's settings: 2,000 bodies, k = 15 (the paper's), seed 1.
    fn default() -> Self {
        BuildOptions { bodies: 2000, components: 15, seed: 1 }
    }
}

/// Reports progress: `(stage, done, total)`.
pub type BuildProgress<'a> = &'a (dyn Fn(&str, usize, usize) + Sync);

/// Why a model could not be built.
#[derive(Debug, thiserror::Error)]
pub enum BuildError {
    /// An asset file is unusable.
    #[error(transparent)]
    MakeHuman(#[from] crate::pose::makehuman::MakeHumanError),
    /// The inputs cannot make a model (named).
    #[error("{0}")]
    Input(String),
}

/// A model from the MakeHuman assets: `options.bodies` sampled adult bodies, mirror-averaged,
/// PCA with `options.components` components; the 21-bone skeleton with cleaned weights; MVC
/// joints on the mean body. At full precision: [`file::at_file_precision`] rounds it as stored.
pub fn from_makehuman(
    mh: &MakeHuman,
    options: &BuildOptions,
    progress: BuildProgress,
) -> Result<BodyModel, BuildError> {
    let input = |e: String| BuildError::Input(format!("{}: {e}", mh.dir.display()));
    if options.bodies < 2 || options.components == 0 {
        return Err(BuildError::Input("a model needs at least 2 bodies and 1 component".into()));
    }
    let base = mh.base.skin(&mh.base.vertices);
    let mirror = template::mirror_map(&base.positions)
        .map_err(|v| input(format!("skin vertex {v} has no mirror partner")))?;
    let population = population::sample(options.bodies, options.seed);
    let mut targets = Vec::with_capacity(population.targets.len());
    for (i, name) in population.targets.iter().enumerate() {
        progress("reading targets", i, population.targets.len());
        targets.push(mh.target(name)?);
    }
    // Each target as a mirror-averaged skin offset (the bodies are mirror-averaged: linear).
    let basis: Vec<Vec<DVec3>> = targets
        .par_iter()
        .map(|t| {
            let mut full = vec![DVec3::ZERO; mh.base.vertices.len()];
            t.apply(&mut full, 1.0);
            template::symmetrised(&mh.base.skin(&full).positions, &mirror)
        })
        .collect();
    progress("principal components", 0, 1);
    let offset = template::symmetrised(&base.positions, &mirror);
    let pcs = pca::principal_components(&offset, &basis, &population.bodies, options.components);
    // The mean body's joints by MakeHuman's rule (the full vertex list: joint cubes included).
    let mut mean_full = mh.base.vertices.clone();
    for (j, t) in targets.iter().enumerate() {
        let c = population.bodies.iter().map(|b| b[j]).sum::<f64>() / options.bodies as f64;
        t.apply(&mut mean_full, c);
    }
    let (skeleton, into) = skeleton::reduce(&mh.rig).map_err(input)?;
    let heads = mh.rig.bone_heads(&mean_full);
    let joints: Vec<DVec3> =
        skeleton.names.iter().map(|n| heads[mh.rig.bone(n).unwrap_or(0)]).collect();
    let quads: Vec<[u32; 4]> = {
        let mut compact = vec![0u32; mh.base.vertices.len()];
        for (k, &v) in mh.base.skin_vertices.iter().enumerate() {
            compact[v as usize] = k as u32;
        }
        mh.base.skin_quads.iter().map(|q| q.map(|v| compact[v as usize])).collect()
    };
    progress("skin weights", 0, 1);
    let weights = skeleton::skin_weights(
        &mh.weights,
        &mh.base.skin_vertices,
        &into,
        &skeleton,
        &quads,
        &mirror,
    );
    let mean_mesh = Mesh::new(pcs.mean.clone(), base.triangles.clone());
    progress("mean value coordinates", 0, 1);
    let regressor = regressor(&mean_mesh, &joints, &skeleton, &mirror);
    let model = assemble(
        mean_mesh,
        mirror,
        pcs,
        skeleton,
        weights,
        regressor,
        Provenance {
            source: "makehuman".into(),
            bodies: options.bodies,
            seed: Some(options.seed),
            total_variance_mm2: 0.0,
        },
    );
    Ok(model)
}

/// A model from registered meshes in `template`'s topology (same vertex count and order):
/// each mirror-averaged, then the PCA; skeleton, weights and regressor are the template's.
pub fn from_meshes(
    template: &BodyModel,
    meshes: &[Vec<DVec3>],
    components: usize,
    progress: BuildProgress,
) -> Result<BodyModel, BuildError> {
    if meshes.len() < 2 {
        return Err(BuildError::Input("a model needs at least 2 meshes".into()));
    }
    let basis: Vec<Vec<DVec3>> =
        meshes.par_iter().map(|m| template::symmetrised(m, &template.mirror)).collect();
    progress("principal components", 0, 1);
    let identity: Vec<Vec<f64>> = (0..meshes.len())
        .map(|i| (0..meshes.len()).map(|j| f64::from(u8::from(i == j))).collect())
        .collect();
    let offset = vec![DVec3::ZERO; template.mean.len()];
    let pcs = pca::principal_components(&offset, &basis, &identity, components);
    let mesh = template.mesh(pcs.mean.clone());
    let model = assemble(
        mesh,
        template.mirror.clone(),
        pcs,
        template.skeleton.clone(),
        template.weights.clone(),
        template.regressor.clone(),
        Provenance {
            source: "meshes".into(),
            bodies: meshes.len(),
            seed: None,
            total_variance_mm2: 0.0,
        },
    );
    Ok(model)
}

/// The MVC regressor (eq. 1) of `joints` on the template `mesh`, mirror-averaged
/// (`m^n_i <- (m^n_i + m^n'_i')/2` for mirror joint n' and vertex i') so that a symmetric body
/// has symmetric joints whatever way its quads were split; on the (symmetric) template it still
/// reproduces the (symmetrised) joints.
fn regressor(
    mesh: &Mesh,
    joints: &[DVec3],
    skeleton: &skeleton::Skeleton,
    mirror: &[u32],
) -> Vec<Vec<f64>> {
    let bone_mirror = skeleton.mirror();
    let joints: Vec<DVec3> = (0..joints.len())
        .map(|n| (joints[n] + template::reflect(joints[bone_mirror[n]])) / 2.0)
        .collect();
    let raw: Vec<Vec<f64>> = joints.par_iter().map(|&j| mvc::coordinates(mesh, j)).collect();
    (0..raw.len())
        .map(|n| {
            (0..mirror.len())
                .map(|i| (raw[n][i] + raw[bone_mirror[n]][mirror[i] as usize]) / 2.0)
                .collect()
        })
        .collect()
}

/// The model from its parts; components scaled by their standard deviations.
fn assemble(
    mesh: Mesh,
    mirror: Vec<u32>,
    pcs: pca::PrincipalComponents,
    skeleton: skeleton::Skeleton,
    weights: crate::pose::skinning::SkinWeights,
    regressor: Vec<Vec<f64>>,
    mut provenance: Provenance,
) -> BodyModel {
    provenance.total_variance_mm2 = pcs.total_variance;
    let sigmas: Vec<f64> = pcs.variances.iter().map(|l| l.sqrt()).collect();
    let components = pcs
        .directions
        .iter()
        .zip(&sigmas)
        .map(|(u, s)| u.iter().map(|d| *d * *s).collect())
        .collect();
    let explained = pcs.variances.iter().map(|l| l / pcs.total_variance).collect();
    BodyModel {
        triangles: mesh.triangles,
        mirror,
        mean: mesh.positions,
        components,
        sigmas,
        explained,
        skeleton,
        weights,
        regressor,
        provenance,
    }
}
