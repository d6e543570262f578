//! Synthetic body scans: a procedural human body with known ground truth, and the artifacts a
//! body scanner adds to it; the pipeline's tests, benches and the demo use them as customers
//! whose every measurement is known.
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
//! Stances ([`Pose`]): each arm from resting on the torso (touching it where it comes
//! closest, see [`BodyParams::with_arm_resting_on_torso`]) to raised past horizontal, swung
//! and bent at the elbow, the shoulder lifted; each leg from together (2 degrees, the thighs
//! blended below the crotch) to 20 degrees out; the spine bent sideways and twisted up to
//! 12 and 15 degrees between the waist and the shoulders, and the head turned (warps of the
//! upright design, `warp.rs`). The truth girths leave the arms out, as a tape passes between
//! an arm and the torso even where the arm rests on it.
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
mod warp;

pub use artifacts::{Artifacts, HoleSite, Units, UpAxis, capture, with_noise_and_holes};
pub use params::{
    ArmPose, BodyParams, DEFAULT_RESOLUTION_MM, LegPose, ParamError, Pose, SpinePose,
};
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
    /// The implicit body the surface was meshed from.
    implicit: body::ImplicitBody,
}

impl SyntheticBody {
    /// How far (mm) the point `p` lies outside the body with its arms left out (negative
    /// inside): the torso, head and legs a tape meets. A point of a torso section more than
    /// a blend's width outside it is arm material.
    pub fn distance_without_arms(&self, p: [f64; 3]) -> f64 {
        self.implicit.value_without_arms(glam::DVec3::from_array(p))
    }

    /// The tape girth (mm) of the horizontal section at height `z` around the point `inside`
    /// (x, y), arms left out, measured on the implicit surface (360 rays, their first exits,
    /// hulled): what a tape measures there, independent of any mesh. `None` if `inside` is
    /// not inside.
    pub fn girth_around(&self, inside: [f64; 2], z: f64) -> Option<f64> {
        calibration::tape_girth_around(&self.implicit, (inside[0], inside[1]), z)
    }

    /// The tape girth (mm) of the section (arms included) by the plane through `centre`
    /// perpendicular to `axis`, around `centre` (360 rays in the plane, their first exits,
    /// hulled): a limb's girth across its axis, measured on the implicit surface. `None` if
    /// `centre` is not inside.
    pub fn girth_across(&self, centre: [f64; 3], axis: [f64; 3]) -> Option<f64> {
        calibration::tape_girth_across(
            &self.implicit,
            glam::DVec3::from_array(centre),
            glam::DVec3::from_array(axis),
        )
    }

    /// The section of the surface (arms included) by the plane through `centre`
    /// perpendicular to `axis`, in space (mm): along each of 360 rays in the plane from
    /// `centre`, the first point where the surface is left. `None` if `centre` is not inside.
    pub fn section_across(&self, centre: [f64; 3], axis: [f64; 3]) -> Option<Vec<[f64; 3]>> {
        let (centre, axis) = (glam::DVec3::from_array(centre), glam::DVec3::from_array(axis));
        calibration::section_across(&self.implicit, centre, axis)
            .map(|points| points.into_iter().map(|p| p.to_array()).collect())
    }

    /// A point on the axis of the leg on the subject's left (`left`) or right side at height
    /// `z` (on the line from the hip joint to the ankle joint): inside the leg below the crotch.
    pub fn leg_axis_at(&self, left: bool, z: f64) -> [f64; 2] {
        let side = if left { &self.truth.landmarks.left } else { &self.truth.landmarks.right };
        let (hip, ankle) =
            (glam::DVec3::from_array(side.hip_joint), glam::DVec3::from_array(side.ankle_joint));
        let p = hip.lerp(ankle, (hip.z - z) / (hip.z - ankle.z));
        [p.x, p.y]
    }

    /// The centre of the torso's section at height `z` (where girth rays start).
    pub fn torso_centre_at(&self, z: f64) -> [f64; 2] {
        let (x, y) = self.implicit.torso_centre(z);
        [x, y]
    }
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
    Ok(SyntheticBody { surface, truth, params: params.clone(), implicit: calibrated.body })
}
