//! Scan to mannequin with pose symmetry first (the paper's whole of section 3): fit the body
//! model to the scan (eq. 4), give the scan the model's rig, re-pose it symmetric (eq. 3)
//! ([`repose`]), measure the scan as it stood ([`measure_as_scanned`]), then the shape symmetry
//! of the pose-symmetric scan: the mannequin alone ([`reconstruct`], for `reconstruct`) or the
//! mannequin with the form fitted to it ([`reconstruct_shape`], for `run` and `demo`).

use crate::body::mesh::{Mesh, grow};
use crate::body::regions::BodyRegions;
use crate::body::scan::Scan;
use crate::body::segmented_body::SegmentedBody;
use crate::pose::body_model::BodyModel;
use crate::pose::model_fit::verdict::{self, NotConverged, RegionResidual};
use crate::pose::model_fit::{self, FitOptions, ModelFit, ModelFitError};
use crate::pose::pose_symmetry::{self, PoseOverrides};
use crate::pose::rig_transfer::{self, RigTransfer};
use crate::run::pipeline::{self, ShapeError, Shaped, Symmetrized};
use crate::shape::mannequin::{MannequinError, MannequinOptions};
use crate::shape::measure::{Comparison, Girth, Measurements, levels, measure_at};
use form_description::FormDescription;
use glam::DVec3;
use serde::Serialize;

/// How to reconstruct.
#[derive(Debug, Clone, Default)]
pub struct ReconstructOptions {
    /// How to fit the model.
    pub fit: FitOptions,
    /// Joint angles set on the symmetric pose.
    pub pose: PoseOverrides,
    /// How to build the mannequin.
    pub mannequin: MannequinOptions,
}

/// The steps of [`repose`], reported to `progress` as they start.
pub const REPOSE_STEPS: [&str; 3] =
    ["fitting the body model", "transferring the rig", "re-posing the scan symmetric"];

/// The step of [`measure_as_scanned`].
pub const AS_SCANNED_STEP: &str = "measuring the scan as it stood";

/// The steps of [`reconstruct`] and [`reconstruct_shape`] before the mannequin's: those of
/// [`repose`], then [`measure_as_scanned`]; [`reconstruct`] goes on with [`pipeline::STEPS`],
/// [`reconstruct_shape`] with [`pipeline::SHAPE_STEPS`].
pub const STEPS: [&str; 4] = [REPOSE_STEPS[0], REPOSE_STEPS[1], REPOSE_STEPS[2], AS_SCANNED_STEP];

/// A scan re-posed symmetric: what [`repose`] made.
#[derive(Debug, Clone)]
pub struct Reposed {
    /// The model as fitted: the one given with its limb segments' lengths as more shape
    /// directions ([`model_fit::segment_lengths`]); `fit`'s beta is its.
    pub model: BodyModel,
    /// The fitted model.
    pub fit: ModelFit,
    /// The symmetric pose (one rotation vector per bone).
    pub symmetric: Vec<DVec3>,
    /// The fit's residual per body region.
    pub residuals: Vec<RegionResidual>,
    /// The scan's skin weights.
    pub rig: RigTransfer,
    /// The pose-symmetric scan (same vertices and triangles as the input, moved).
    pub posed: Scan,
    /// The fit's wall time (s).
    pub fit_seconds: f64,
}

/// The input scan measured as it stood, before pose symmetry: what [`measure_as_scanned`]
/// found, the scan's column of `measurements.json` and of the ring table.
#[derive(Debug, Clone)]
pub struct AsScanned {
    /// The scan's segmentation, where it can be segmented as it stands.
    pub regions: Option<BodyRegions>,
    /// The scan's own measurements, where it can be segmented as it stands.
    pub measurements: Option<Measurements>,
}

/// What [`reconstruct`] made: the re-posed scan, the input measured as it stood and the
/// mannequin.
#[derive(Debug, Clone)]
pub struct Reconstruction {
    /// The fit and the pose-symmetric scan.
    pub reposed: Reposed,
    /// The input scan as it stood.
    pub as_scanned: AsScanned,
    /// The pose-symmetric scan's mannequin and measurements.
    pub result: Symmetrized,
}

/// What [`reconstruct_shape`] made: the re-posed scan, its mannequin and the form fitted to
/// it.
#[derive(Debug, Clone)]
pub struct Reshaped {
    /// The fit and the pose-symmetric scan.
    pub reposed: Reposed,
    /// The input scan as it stood.
    pub as_scanned: AsScanned,
    /// The mannequin of the pose-symmetric scan, the form's fit and set-points, and the
    /// pose-symmetric scan's and the mannequin's girths at every ring.
    pub shaped: Shaped,
    /// The input scan's tape girth at every ring (form order; `None` where it has no section
    /// there or cannot be segmented as it stands), at the height the ring shapes on the
    /// pose-symmetric scan.
    pub scan_rings: Vec<Option<f64>>,
}

/// Why a reconstruction failed.
#[derive(Debug, thiserror::Error)]
pub enum ReconstructError {
    /// The fit could not run.
    #[error(transparent)]
    Fit(#[from] ModelFitError),
    /// The fit ran but does not match the scan.
    #[error(transparent)]
    NotConverged(#[from] NotConverged),
    /// The pose-symmetric scan gave no mannequin.
    #[error("the pose-symmetric scan: {0}")]
    Mannequin(#[from] MannequinError),
    /// The form could not be fitted to the mannequin.
    #[error("the pose-symmetric scan: {0}")]
    Shape(#[from] ShapeError),
}

/// Fits `model` to `scan` (canonical frame), gives the scan the model's rig and re-poses it
/// symmetric, calling `progress(step)` before each of [`REPOSE_STEPS`]. A fit that does not match
/// the scan is an error ([`NotConverged`]), never a re-posed body.
pub fn repose(
    scan: &Scan,
    model: &BodyModel,
    options: &ReconstructOptions,
    mut progress: impl FnMut(usize),
) -> Result<Reposed, ReconstructError> {
    progress(0);
    let extended = model_fit::segment_lengths::extended(model);
    let model = &extended;
    let body = &scan.body;
    let start = std::time::Instant::now();
    let fitted = model_fit::fit(model, &model_fit::ScanPoints::of_mesh(body), &options.fit)?;
    let fit_seconds = start.elapsed().as_secs_f64();
    let residuals = verdict::residuals(model, &fitted, &body.positions);
    verdict::verdict(&residuals)?;

    progress(1);
    let fitted_mesh = model.mesh(fitted.vertices(model));
    let bones = model.skeleton.names.len();
    let rig = rig_transfer::transfer(body, &fitted_mesh, &model.weights, bones);

    progress(2);
    let mut symmetric =
        pose_symmetry::symmetric(&fitted.theta, &model.skeleton, options.pose.limbs);
    options.pose.apply(&mut symmetric, &model.skeleton);
    let moved = pose_symmetry::repose(
        &body.positions,
        &rig.weights,
        &model.skeleton.parents,
        &model.joints(&fitted.beta),
        &fitted.theta,
        &symmetric,
        fitted.translation,
    );
    let mut posed = scan.clone();
    posed.body.positions = moved;
    tear_fused_skin(&body.positions, &mut posed.body);
    // The symmetric legs stand a little higher or lower: the body moved so that its feet stand
    // where the scan's did, the move recorded in the frame (so `--scan-frame` writes it back
    // where the scan stood).
    let drop = feet_drop(model, &fitted, &symmetric);
    posed.frame.translate(&mut posed.body, DVec3::Z * drop);
    posed.frame.centre_on_torso(&mut posed.body);
    Ok(Reposed { model: extended, fit: fitted, symmetric, residuals, rig, posed, fit_seconds })
}

/// How many times its scanned length an edge of the re-posed scan may be stretched: where two
/// parts touched as the customer stood (an arm hanging against the torso) the scan's surface
/// joins them, and re-posing pulls that join out into a web between the arm and the torso
/// (on MakeHuman bodies with both arms 0-5 degrees from hanging: webs down to 40-70 mm below
/// the armpit, ledges on the mannequin). Chosen on issue 35's 40 MakeHuman bodies: at 4 the
/// webs stayed; at 3 two of the three bodies with webs kept ledges (width jumps 28 and 21 mm);
/// at 2 one kept a lip (gone with [`TORN_SPREAD`]); the slightly posed bodies' girths did not
/// move at any of them.
const TORN_STRETCH: f64 = 2.0;
/// A tear runs on through the triangles around it stretched more than this: the skin next to
/// a web is pulled out less but still far (blended weights share the arm's move between
/// rows), and left standing it was a lip 20-45 mm out of the torso's side under the arm
/// plates (issue 35's body 35, both arms 0-2 degrees from hanging: width jump 32 mm, 43
/// self-intersecting pairs). Chosen on the three bodies of the 40 with webs: at 1.7 none
/// kept a lip or a self-intersection; at 1.4-1.5 body 20 had 8 self-intersecting pairs, at
/// 1.3 body 35 a 17 mm jump (1.6 and 1.8 not tried). The spread has no reach limit: skin
/// stretched over 1.7 times that touches a web goes too, wherever it is (on the demo's scan,
/// 44 of 298,252 triangles go in all, 24 without the spread).
const TORN_SPREAD: f64 = 1.7;
/// Edges shorter than this as scanned (mm) count as this long: a sliver's stretch means nothing.
const TORN_MIN_EDGE_MM: f64 = 1.0;

/// Drops the triangles of `mesh` (the re-posed scan) any of whose edges stretched more than
/// [`TORN_STRETCH`] times from `scanned` (the same vertices as scanned), and those stretched
/// more than [`TORN_SPREAD`] times reached from them through shared vertices (a hysteresis
/// threshold, as an edge detector's): the web is cut open, leaving a hole as a scanner's,
/// which slicing bridges. The vertices stay (the rig's weights are per vertex).
fn tear_fused_skin(scanned: &[DVec3], mesh: &mut Mesh) {
    let positions = &mesh.positions;
    let stretch = |&[a, b, c]: &[u32; 3]| {
        let edge = |a: u32, b: u32| {
            let before = scanned[a as usize].distance(scanned[b as usize]).max(TORN_MIN_EDGE_MM);
            positions[a as usize].distance(positions[b as usize]) / before
        };
        edge(a, b).max(edge(b, c)).max(edge(c, a))
    };
    let stretch: Vec<f64> = mesh.triangles.iter().map(stretch).collect();
    let seeds: Vec<bool> = stretch.iter().map(|&s| s > TORN_STRETCH).collect();
    let torn = grow(mesh, &seeds, |t| stretch[t] > TORN_SPREAD);
    let kept = mesh.triangles.iter().zip(torn).filter(|(_, torn)| !torn);
    mesh.triangles = kept.map(|(t, _)| *t).collect();
}

/// Measures `scan` (canonical frame) as it stands, where it can be segmented so: the column
/// the pose-symmetric scan's measurements are compared with.
pub fn measure_as_scanned(scan: &Scan) -> AsScanned {
    let body = SegmentedBody::find(&scan.body).ok();
    let measurements = body.as_ref().map(|body| measure_at(body, &levels(body)));
    AsScanned { regions: body.map(SegmentedBody::into_regions), measurements }
}

impl AsScanned {
    /// The tape girth of `scan` (the body this was measured on) for each ring of `form`, at
    /// the body heights `heights` give, as [`pipeline::girths_at_rings`]; all `None` where the
    /// scan could not be segmented as it stood.
    pub fn girths_at_rings(
        &self,
        scan: &Scan,
        form: &FormDescription,
        heights: &[f64],
    ) -> Vec<Option<f64>> {
        match &self.regions {
            Some(regions) => {
                let body = SegmentedBody::with_regions(&scan.body, regions);
                pipeline::girths_at_rings(&body, form, heights)
            }
            None => vec![None; heights.len()],
        }
    }
}

/// Reconstructs the mannequin of `scan` (canonical frame) with `model`, calling
/// `progress(step)` before each step (indices into [`STEPS`] then [`pipeline::STEPS`]).
pub fn reconstruct(
    scan: &Scan,
    model: &BodyModel,
    options: &ReconstructOptions,
    mut progress: impl FnMut(usize),
) -> Result<Reconstruction, ReconstructError> {
    let (reposed, as_scanned) = repose_and_measure(scan, model, options, &mut progress);
    let reposed = reposed?;
    progress(REPOSE_STEPS.len());
    let result =
        pipeline::symmetrize(&reposed.posed, &options.mannequin, |s| progress(STEPS.len() + s))?;
    Ok(Reconstruction { reposed, as_scanned, result })
}

/// The whole chain of `run` and `demo`: [`repose`], [`measure_as_scanned`], then the mannequin
/// of the pose-symmetric scan with `form` fitted to it ([`pipeline::shape`]), and the input
/// scan's girths at the rings beside the pose-symmetric scan's; `progress(step)` before each step (indices into
/// [`STEPS`] then [`pipeline::SHAPE_STEPS`]).
pub fn reconstruct_shape(
    scan: &Scan,
    model: &BodyModel,
    options: &ReconstructOptions,
    form: &FormDescription,
    mut progress: impl FnMut(usize),
) -> Result<Reshaped, ReconstructError> {
    let (reposed, as_scanned) = repose_and_measure(scan, model, options, &mut progress);
    let reposed = reposed?;
    progress(REPOSE_STEPS.len());
    let shaped =
        pipeline::shape(&reposed.posed, &options.mannequin, form, |s| progress(STEPS.len() + s))?;
    // The pose-symmetric scan's frame is the input's moved by the feet's drop (and centred):
    // a ring's height on the input is its height there less that move.
    let dz =
        reposed.posed.frame.file_frame().translation[2] - scan.frame.file_frame().translation[2];
    let heights: Vec<f64> = shaped.rings.iter().map(|r| r.body_z_mm - dz).collect();
    let scan_rings = as_scanned.girths_at_rings(scan, form, &heights);
    Ok(Reshaped { reposed, as_scanned, shaped, scan_rings })
}

/// [`repose`] and [`measure_as_scanned`] at once: the measuring needs nothing of the fit, and
/// fills the cores that the fit's and the rig transfer's one-thread steps leave idle.
fn repose_and_measure(
    scan: &Scan,
    model: &BodyModel,
    options: &ReconstructOptions,
    progress: impl FnMut(usize),
) -> (Result<Reposed, ReconstructError>, AsScanned) {
    let mut as_scanned = None;
    let reposed = rayon::in_place_scope(|s| {
        s.spawn(|_| as_scanned = Some(measure_as_scanned(scan)));
        repose(scan, model, options, progress)
    });
    (reposed, as_scanned.expect("the scope ran the measuring"))
}

/// How far re-posing from `fitted.theta` to `symmetric` lowers the feet (mm; negative when it
/// raises them): measured on the fitted model, whose soles are whole, not on the scan, whose
/// soles a scanner cuts at the floor plane (a foot lifted sideways keeps more of its sole, so
/// the scan's lowest point after re-posing is not a sole's).
fn feet_drop(model: &BodyModel, fitted: &ModelFit, symmetric: &[DVec3]) -> f64 {
    let lowest = |theta: &[DVec3]| {
        let body = model.posed(&fitted.beta, theta, fitted.translation);
        body.iter().map(|p| p.z).fold(f64::INFINITY, f64::min)
    };
    lowest(&fitted.theta) - lowest(symmetric)
}

/// `measurements.json`: the paper's Table 1 with three columns (the scan as it stood, the
/// pose-symmetric scan, the mannequin), and the pose-symmetric scan's full comparison.
#[derive(Debug, Clone, Serialize)]
pub struct MeasurementsReport<'a> {
    /// Chest, waist and hip.
    pub table: Vec<ThreeColumns>,
    /// The input scan's measurements (`null` when it cannot be segmented as it stands).
    pub scan: Option<&'a Measurements>,
    /// Table 1 and Fig. 11 of the pose-symmetric scan and its mannequin.
    pub pose_symmetric: &'a Comparison,
}

/// One row of the three-column Table 1.
#[derive(Debug, Clone, Serialize)]
pub struct ThreeColumns {
    /// "chest", "waist" or "hip".
    pub measure: &'static str,
    /// The scan as it stood (at its own level), if it could be measured.
    pub scan: Option<Girth>,
    /// The pose-symmetric scan.
    pub pose_symmetric: Girth,
    /// The mannequin, at the pose-symmetric scan's level.
    pub mannequin: Girth,
}

/// `fit.json`: what the fit found and what the symmetric pose is. Not the fit's wall time: the
/// same scan gives the same bytes (the commands print the time).
#[derive(Debug, Clone, Serialize)]
pub struct FitReport {
    /// Per bone: fitted and symmetric rotation vectors (degrees; see docs/formats.md, `fit.json`).
    pub joints: Vec<JointAngles>,
    /// The shape coefficients (standard deviations), the last ones the limb segments' lengths
    /// ([`model_fit::segment_lengths`]).
    pub beta: Vec<f64>,
    /// The global translation (mm, canonical frame).
    pub translation_mm: [f64; 3],
    /// Root mean square distances of the last iteration's pairs.
    pub residuals: model_fit::Residuals,
    /// Per body region, the distance of the model to the scan, and the verdict's limit.
    pub regions: Vec<RegionResidual>,
    /// LM iterations.
    pub iterations: usize,
    /// Scan vertices whose skin weights were filled from their neighbours.
    pub rig_filled_vertices: usize,
}

/// One bone's angles in `fit.json`.
#[derive(Debug, Clone, Serialize)]
pub struct JointAngles {
    /// The bone's name.
    pub name: String,
    /// The fitted rotation vector (degrees).
    pub fitted_deg: [f64; 3],
    /// The symmetric pose's (degrees).
    pub symmetric_deg: [f64; 3],
}

impl<'a> MeasurementsReport<'a> {
    /// `measurements.json`: the scan `as_scanned`, and the pose-symmetric scan's comparison
    /// `c` with its mannequin.
    pub fn new(as_scanned: &'a AsScanned, c: &'a Comparison) -> MeasurementsReport<'a> {
        let scan = as_scanned.measurements.as_ref();
        let table = c
            .table
            .iter()
            .map(|row| ThreeColumns {
                measure: row.measure,
                scan: scan.map(|m| match row.measure {
                    "chest" => m.chest,
                    "waist" => m.waist,
                    _ => m.hip,
                }),
                pose_symmetric: row.input,
                mannequin: row.mannequin,
            })
            .collect();
        MeasurementsReport { table, scan, pose_symmetric: c }
    }
}

impl Reposed {
    /// `fit.json`.
    pub fn fit_report(&self) -> FitReport {
        let model = &self.model;
        let deg = |v: DVec3| (v * 180.0 / std::f64::consts::PI).to_array();
        let joints = (model.skeleton.names.iter().enumerate())
            .map(|(b, name)| JointAngles {
                name: name.clone(),
                fitted_deg: deg(self.fit.theta[b]),
                symmetric_deg: deg(self.symmetric[b]),
            })
            .collect();
        FitReport {
            joints,
            beta: self.fit.beta.clone(),
            translation_mm: self.fit.translation.to_array(),
            residuals: self.fit.residuals,
            regions: self.residuals.clone(),
            iterations: self.fit.iterations,
            rig_filled_vertices: self.rig.filled,
        }
    }

    /// `rigged.glb`: the input scan with the skeleton at its fitted joints and its weights.
    pub fn rigged_glb(&self, scan: &Scan) -> Vec<u8> {
        let model = &self.model;
        let joints = self.fit.joints(model);
        crate::pose::body_model::file::rigged_to_bytes(
            &scan.body,
            &self.rig.weights,
            &model.skeleton,
            &joints,
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A strip of triangles along x, 10 mm per step: vertices `2i` at y = 0 and `2i + 1` at
    /// y = 10, triangle pairs `[2i, 2i+2, 2i+1]`, `[2i+1, 2i+2, 2i+3]`.
    fn strip(steps: usize) -> Mesh {
        let positions = (0..2 * (steps + 1))
            .map(|v| DVec3::new(10.0 * (v / 2) as f64, 10.0 * (v % 2) as f64, 0.0))
            .collect();
        let triangles = (0..steps as u32)
            .flat_map(|i| [[2 * i, 2 * i + 2, 2 * i + 1], [2 * i + 1, 2 * i + 2, 2 * i + 3]])
            .collect();
        Mesh { positions, triangles }
    }

    #[test]
    fn a_web_tears_and_the_tear_spreads_only_through_stretched_skin() {
        // Six steps; columns move out along x: the step from 10 to 20 mm stretches 2.5 times
        // (a web), the next 1.8 times (beside the web), then one unstretched, one 1.8 times
        // (apart from the web), one unstretched.
        let scanned = strip(6);
        let mut mesh = scanned.clone();
        let shift = [0.0, 0.0, 15.0, 23.0, 23.0, 31.0, 31.0];
        for (v, p) in mesh.positions.iter_mut().enumerate() {
            p.x += shift[v / 2];
        }
        tear_fused_skin(&scanned.positions, &mut mesh);
        // The web and the skin beside it go; the stretched skin away from it stays.
        let left: Vec<u32> = mesh.triangles.iter().map(|t| t[0] / 2).collect();
        assert_eq!(left, [0, 0, 3, 3, 4, 4, 5, 5]);
    }
}
