//! Fitting the body model to a scan (paper 3.1.2, eq. 4): find the shape `beta`, the joint
//! angles `theta` and the global translation that make `M(theta, beta)` (eq. 3) match the scan
//! points, with no landmarks.
//!
//! Robust ICP with a Levenberg-Marquardt step ([`lm`]): closest points both ways
//! ([`correspondences`]), point-to-plane plus a little point-to-point, pairs rejected where the
//! normals disagree or the scan point lies on a hole's boundary, Geman-McClure weights
//! ([`robust`]) annealed coarse to fine; eq. 4's regularisers ([`priors`]): a prior on beta,
//! joint limits ([`joint_limits`]), a smoothness prior along the spine (and on to the neck's
//! sideways bend), a weak pull of the angles to rest (not the upper arms' abduction). Coarse to fine in the unknowns as well
//! ([`STAGES`]): global placement and shape, then spine, shoulders, arms, elbows and hips,
//! then every bone. Before the limbs are freed the arms try several abductions ([`arm_starts`]) against
//! the local minimum of an arm matched to the torso.
//!
//! ```no_run
//! use dressform::{pose::body_model::BodyModel, pose::model_fit};
//! # let scan = dressform::body::mesh::Mesh::new(vec![], vec![]);
//! let model = BodyModel::builtin();
//! let points = model_fit::ScanPoints::of_mesh(&scan);
//! let fitted = model_fit::fit(&model, &points, &model_fit::FitOptions::default())?;
//! println!("{} iterations, beta {:?}", fitted.iterations, fitted.beta);
//! # Ok::<(), dressform::pose::model_fit::ModelFitError>(())
//! ```

pub mod arm_starts;
pub mod correspondences;
pub mod joint_limits;
pub mod lm;
pub mod params;
pub mod priors;
pub mod robust;
pub mod segment_lengths;
pub mod verdict;

use correspondences::ScanCloud;
pub use correspondences::ScanPoints;
use glam::DVec3;
use params::{Params, PreparedModel, vertex_normals};

/// Which bones a stage frees (besides the translation, the root's rotation and beta).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Bones {
    /// Only the global placement and the shape.
    Global,
    /// Also the spine, clavicles, upper arms, elbows and upper legs.
    Core,
    /// Every bone.
    All,
}

/// One stage of the coarse-to-fine schedule.
#[derive(Debug, Clone, Copy)]
pub struct Stage {
    /// The bones it frees.
    pub bones: Bones,
    /// The Geman-McClure scale (mm).
    pub sigma_mm: f64,
    /// At most this many iterations (each with fresh correspondences).
    pub iterations: usize,
}

/// The schedule: the scale starts at the size of a limb's misplacement in the mean model's
/// A-pose (~50 mm) and ends a little above a scanner's noise and the model's vertex spacing
/// (~10 mm), so that the fine stage ignores holes and clothing folds.
pub const STAGES: [Stage; 3] = [
    Stage { bones: Bones::Global, sigma_mm: 50.0, iterations: 10 },
    Stage { bones: Bones::Core, sigma_mm: 25.0, iterations: 12 },
    Stage { bones: Bones::All, sigma_mm: 10.0, iterations: 15 },
];

/// A stage ends when an iteration lowers the energy by less than this fraction.
const CONVERGED: f64 = 1e-4;

/// The bones [`Bones::Core`] frees, by name (the root is always free). The elbows are among
/// them: the model's rest elbow is bent 46.6 degrees, a customer's in the A-pose about 10, so
/// the forearm starts up to 90 mm off the scan at the wrist; freed only in the fine stage
/// (scale 10 mm) its pairs weighed nothing and it stayed bent (the sim generator's demo
/// customer: arms 12.2 and 9.6 mm from the scan, forearms 34 degrees off; freed here, 7.3 and
/// 6.6 mm, 6 degrees).
const CORE_BONES: [&str; 12] = [
    "spine04",
    "spine03",
    "spine02",
    "spine01",
    "clavicle.L",
    "upperarm01.L",
    "lowerarm01.L",
    "clavicle.R",
    "upperarm01.R",
    "lowerarm01.R",
    "upperleg01.L",
    "upperleg01.R",
];

/// How to fit.
#[derive(Debug, Clone)]
pub struct FitOptions {
    /// The fraction of scan points used for scan-to-model pairs (the paper's Fig. 4: 10%).
    pub sample_fraction: f64,
    /// The coarse-to-fine schedule.
    pub stages: Vec<Stage>,
}

impl Default for FitOptions {
    fn default() -> Self {
        FitOptions { sample_fraction: 0.1, stages: STAGES.to_vec() }
    }
}

/// How well the fit matches (from the last iteration's pairs).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Residuals {
    /// Root mean square point-to-plane distance, model vertices to the scan (mm).
    pub model_to_scan_mm: f64,
    /// The same, sampled scan points to the model (mm).
    pub scan_to_model_mm: f64,
    /// The energy of eq. 4 at the end (mm^2, mean per pair plus priors).
    pub energy: f64,
}

/// A fitted model: `M(theta, beta) + translation` (eq. 3).
#[derive(Debug, Clone, PartialEq)]
pub struct ModelFit {
    /// The shape coefficients.
    pub beta: Vec<f64>,
    /// One rotation vector per bone (convention of [`crate::pose::skinning`]).
    pub theta: Vec<DVec3>,
    /// The global translation (mm).
    pub translation: DVec3,
    /// How well it matches.
    pub residuals: Residuals,
    /// LM iterations over all stages.
    pub iterations: usize,
}

impl ModelFit {
    /// The fitted body's vertices.
    pub fn vertices(&self, model: &crate::pose::body_model::BodyModel) -> Vec<DVec3> {
        model.posed(&self.beta, &self.theta, self.translation)
    }

    /// Each bone's posed joint (where it turns), in the scan's frame.
    pub fn joints(&self, model: &crate::pose::body_model::BodyModel) -> Vec<DVec3> {
        let rest = model.joints(&self.beta);
        let g = crate::pose::skinning::bone_transforms(
            &model.skeleton.parents,
            &rest,
            &self.theta,
            self.translation,
        );
        g.iter().zip(&rest).map(|(g, j)| g.transform_point3(*j)).collect()
    }
}

/// Why a fit could not run.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum ModelFitError {
    /// Points and normals differ in number, or there are too few points.
    #[error("{0}")]
    Input(String),
}

/// The fewest scan points a fit accepts: below this a body is not resolved (a few points per
/// model triangle's worth of surface).
pub const MIN_POINTS: usize = 1000;

/// Fits `model` to `scan` (canonical frame: mm, Z up, facing -Y), starting from the mean model
/// at rest placed on the scan's bounding box.
pub fn fit(
    model: &crate::pose::body_model::BodyModel,
    scan: &ScanPoints,
    options: &FitOptions,
) -> Result<ModelFit, ModelFitError> {
    let (points, normals) = (scan.points, &scan.normals);
    if points.len() != normals.len() || points.len() != scan.on_hole_boundary.len() {
        return Err(ModelFitError::Input(format!(
            "{} points, {} normals and {} hole-boundary flags",
            points.len(),
            normals.len(),
            scan.on_hole_boundary.len()
        )));
    }
    if points.len() < MIN_POINTS {
        return Err(ModelFitError::Input(format!(
            "{} points; a body needs at least {MIN_POINTS}",
            points.len()
        )));
    }
    let prep = PreparedModel::new(model);
    let priors = priors::Priors::new(&model.skeleton);
    let stride = (1.0 / options.sample_fraction.clamp(1e-3, 1.0)).round() as usize;
    let cloud = ScanCloud::new(scan, stride);
    let centre = |p: &[DVec3]| {
        let b = crate::body::mesh::Aabb::around(p.iter().copied()).expect("not empty");
        (b.min + b.max) / 2.0
    };
    let mut params = prep.start(centre(points) - centre(&model.mean));
    let mut iterations = 0;
    let mut last = None;
    for (s, stage) in options.stages.iter().enumerate() {
        let active = active(&prep, stage.bones);
        // The arms' starts before the global placement too: placed with both arms at rest, a
        // body with one arm hanging and the other near horizontal tilted the whole model 33
        // degrees sideways to lay its arms along the scan's, and its legs never came back.
        let first = s == 0;
        if first || (stage.bones != Bones::Global && options.stages[s - 1].bones == Bones::Global) {
            params = arm_starts::best(&prep, &cloud, params, stage.sigma_mm);
        }
        let mut lambda = lm::LAMBDA_START;
        for _ in 0..stage.iterations {
            let posed = prep.pose(&params);
            let normals = vertex_normals(&posed.vertices, &model.triangles);
            let data = correspondences::gather(&cloud, &posed.vertices, &normals, stage.sigma_mm);
            let step = lm::iterate(&prep, &priors, &data, &params, &posed, &active, lambda);
            iterations += 1;
            params = step.params;
            lambda = step.lambda;
            last = Some((data.rms_mm, step.after));
            if step.before - step.after <= CONVERGED * step.before {
                break;
            }
        }
    }
    let (rms, energy) = last.unwrap_or(([f64::NAN; 2], f64::NAN));
    let Params { translation, theta, beta } = params;
    Ok(ModelFit {
        beta,
        theta,
        translation,
        residuals: Residuals { model_to_scan_mm: rms[0], scan_to_model_mm: rms[1], energy },
        iterations,
    })
}

/// Which parameters a stage frees.
fn active(prep: &PreparedModel, bones: Bones) -> Vec<bool> {
    let layout = prep.layout;
    let names = &prep.model.skeleton.names;
    let mut on = vec![false; layout.size()];
    on[..3].iter_mut().for_each(|a| *a = true);
    for (b, name) in names.iter().enumerate() {
        let free = b == 0
            || match bones {
                Bones::Global => false,
                Bones::Core => CORE_BONES.contains(&name.as_str()),
                Bones::All => true,
            };
        if free {
            on[layout.bone(b)..layout.bone(b) + 3].iter_mut().for_each(|a| *a = true);
        }
    }
    (0..layout.k).for_each(|k| on[layout.beta(k)] = true);
    on
}
