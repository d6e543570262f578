//! Posing a MakeHuman body with the full 163-bone rig and its own skin weights, by linear
//! blend skinning ([`crate::pose::skinning`], where the angle convention is documented).

use super::{MakeHuman, MakeHumanError};
use crate::pose::skinning;
use glam::DVec3;

/// A pose of the MakeHuman rig: rotation vectors (radians, canonical axes, about each bone's
/// joint in the rest pose, relative to the parent; see [`crate::pose::skinning`]) for named bones,
/// the others at rest, then a global translation (mm). The rest pose is MakeHuman's A-pose.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Pose {
    /// `(bone name, rotation vector)`; a bone named twice gets both rotations, composed in
    /// order (the later one applied after).
    pub rotations: Vec<(String, DVec3)>,
    /// Added to every vertex after the rotations.
    pub translation: DVec3,
}

impl Pose {
    /// The rest pose (every bone at rest, no translation).
    pub fn rest() -> Self {
        Pose::default()
    }

    /// This pose with bone `bone` turned by rotation vector `theta` (radians).
    pub fn rotate(mut self, bone: &str, theta: DVec3) -> Self {
        self.rotations.push((bone.to_string(), theta));
        self
    }

    /// This pose moved by `offset` (mm).
    pub fn translate(mut self, offset: DVec3) -> Self {
        self.translation += offset;
        self
    }
}

/// Poses the full vertex list `vertices` (see [`MakeHuman::pose`]).
pub(super) fn apply(
    mh: &MakeHuman,
    vertices: &[DVec3],
    pose: &Pose,
) -> Result<Vec<DVec3>, MakeHumanError> {
    if vertices.len() != mh.base.vertices.len() {
        return Err(MakeHumanError::new(
            &mh.dir.join("base.obj"),
            format!(
                "a body to pose needs all {} vertices, not {}",
                mh.base.vertices.len(),
                vertices.len()
            ),
        ));
    }
    let mut theta = vec![DVec3::ZERO; mh.rig.bones.len()];
    for (name, rotation) in &pose.rotations {
        let bone = mh.rig.bone(name).ok_or_else(|| {
            MakeHumanError::new(&mh.dir.join("rigs/default.mhskel"), format!("no bone `{name}`"))
        })?;
        // Compose rotations as matrices (rotation vectors do not add).
        let composed = skinning::rotation(*rotation) * skinning::rotation(theta[bone]);
        theta[bone] = glam::DQuat::from_mat3(&composed).to_scaled_axis();
    }
    let joints = mh.rig.bone_heads(vertices);
    let g = skinning::bone_transforms(&mh.rig.parents(), &joints, &theta, pose.translation);
    Ok(skinning::skin(vertices, &mh.weights, &g))
}
