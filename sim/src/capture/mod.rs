//! Simulated capture: a procedural human body with known ground truth, and the artifacts a
//! body scanner adds to it.
//!
//! [`generate`] builds a smooth implicit body (a loft of superellipse sections for the torso
//! with breasts and buttocks; tapered tubes for the limbs; ellipsoids and round cones for head,
//! shoulders, hands and feet; all joined by polynomial smooth unions), calibrates the torso on
//! the implicit surface so the tape girths at the chest, waist and hip levels and the crotch
//! height are what was asked (to 0.002% and 0.02 mm), and meshes it into one closed, manifold,
//! outward-oriented triangle surface (face-consistent marching cubes, see `mesher.rs`).
//! At the default 4 mm grid an adult has about 300,000 triangles and takes about 0.3 s in a
//! release build. [`capture`] then adds scanner artifacts.
//!
//! Frame of [`generate`]'s output: millimetres, Z up, floor at z = 0, +X = the subject's
//! left, the subject faces -Y; x = 0 is the mid-sagittal plane, y = 0 the mid-depth of the
//! waist section.

mod anatomy;
mod artifacts;
mod body;
mod calibration;
mod clearance;
mod mesher;
mod params;
mod primitives;
mod surface;
mod torso;
mod truth;

pub use artifacts::{Artifacts, HoleSite, Units, UpAxis, capture};
pub use params::{ArmPose, BodyParams, DEFAULT_RESOLUTION_MM, LegPose, ParamError, Pose};
pub use surface::TriangleSurface;
pub use truth::{GirthLevel, GroundTruth, Landmarks, SideLandmarks};

/// A generated body: its surface and what it is known to measure.
#[derive(Debug, Clone, PartialEq)]
pub struct SyntheticBody {
    /// Closed, manifold, outward-oriented surface in the canonical frame (mm, Z up).
    pub surface: TriangleSurface,
    /// Measurements and landmarks of the body, in the same frame.
    pub truth: GroundTruth,
    /// The parameters the body was generated from.
    pub params: BodyParams,
}

/// Generates the body described by `params`: validates them, designs and calibrates the
/// implicit body, meshes it at `params.resolution_mm` and measures its ground truth.
pub fn generate(params: &BodyParams) -> Result<SyntheticBody, ParamError> {
    params.validate()?;
    let anatomy = anatomy::Anatomy::new(params);
    let calibrated = calibration::calibrate(&anatomy)?;
    let body = &calibrated.body;
    let surface =
        mesher::mesh_isosurface(&|p| body.value(p), params.resolution_mm, &body.interior_points());
    let truth = truth::ground_truth(&anatomy, &calibrated);
    Ok(SyntheticBody { surface, truth, params: params.clone() })
}
