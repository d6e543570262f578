//! Pose symmetry (paper 3.1.2): the fitted joint angles made left/right symmetric, and the
//! scan re-posed to them with linear blend skinning (eq. 3).
//!
//! Angles follow [`crate::pose::skinning`]: per bone a rotation vector relative to its parent, in the
//! rest frame's axes (X the subject's left, Y backwards, Z up). Mirroring the body about the
//! plane x = 0 maps a rotation vector `(x, y, z)` to `(x, -y, -z)` (a reflection `M` turns the
//! rotation `R` into `M R M`, whose vector is `det(M) M w`). So the symmetric pose is:
//! - a bone on the midline (root, spine, neck, head) keeps only its turn about X, the forward
//!   bend: its sideways bend (about Y) and its twist or turn (about Z) go to zero;
//! - a left/right pair (arms, legs) stands at the body model's rest in the frontal plane and
//!   untwisted ([`Limbs::Rest`], the default): the same stance for every customer however
//!   they stood, and the stance the model's shapes and weights come from (MakeHuman's rest:
//!   arms 40 degrees out, legs 8); its forward bend (about X: a hip flexed against a pelvis
//!   tilted forward, a knee, an arm swung) is the mean of the two sides', as the midline
//!   keeps its own. Or, as the paper does (`limbs = "mean"` in a pose file, [`Limbs::Mean`]),
//!   the whole rotation is the mean of the left angle and the mirrored right one, the right
//!   bone the mirror of that mean.
//!
//! Why not the paper's mean (issue 35): the torso's shape under the arms and its height above
//! the floor follow the limbs. On 4 MakeHuman bodies standing slightly asymmetric (an arm
//! 11-17 degrees further out, a leg 3-8), the mean stance put the pose-symmetric scan's chest
//! +7 to +16 mm over the same body un-posed at its chest level (the arms further out stretch the
//! skin under them; the legs further out lower the crotch 4-8 mm), the waist up to -13; at the
//! rest stance the waist and hip came within 1 mm (`tests/mannequin_population.rs`).
//!
//! Why the forward bend is kept: the fit shares a body's upright stance between its pelvis
//! and its thighs (on one MakeHuman body standing at rest: the pelvis tilted 2.2 degrees
//! forward, both hips 2.5 back). Setting the thighs to rest while the pelvis keeps its tilt
//! leant the whole torso forward, and a level tape round a leant chest is longer or shorter:
//! the chest of 20 slightly posed bodies came out -14 to +11 mm off.
//!
//! A `pose.toml` ([`PoseOverrides`]) then sets any named joint; the re-posed scan is the scan
//! moved, bone by bone, from the fitted pose to that one ([`repose`]).

use crate::input::InputError;
use crate::pose::body_model::Skeleton;
use crate::pose::skinning::{self, SkinWeights};
use glam::DVec3;
use std::collections::BTreeMap;
use std::path::Path;

/// The largest joint angle a pose file may set (degrees): a rotation vector's length is at
/// most a half turn.
pub const MAX_OVERRIDE_DEG: f64 = 180.0;

/// The mirror image of a bone rotation about the plane x = 0 (see the module documentation).
pub fn mirror(theta: DVec3) -> DVec3 {
    DVec3::new(theta.x, -theta.y, -theta.z)
}

/// Where the symmetric pose puts the arms and legs (see the module documentation).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Limbs {
    /// At the body model's rest, sideways and in twist (the same stance for every scan); the
    /// forward bend the mean of the two sides'.
    #[default]
    Rest,
    /// At the mean of the two sides (the paper's).
    Mean,
}

/// The symmetric pose of `theta` (see the module documentation). Rotation vectors are
/// averaged component by component, so a midline bone keeps exactly its forward bend `x`.
pub fn symmetric(theta: &[DVec3], skeleton: &Skeleton, limbs: Limbs) -> Vec<DVec3> {
    let partner = skeleton.mirror();
    let mean = |b: usize| (theta[b] + mirror(theta[partner[b]])) / 2.0;
    (0..theta.len())
        .map(|b| {
            // The second bone of a pair takes the mirror of the first's mean: exactly symmetric.
            let m = if partner[b] < b { mirror(mean(partner[b])) } else { mean(b) };
            match (partner[b] == b, limbs) {
                (false, Limbs::Rest) => DVec3::new(m.x, 0.0, 0.0),
                _ => m,
            }
        })
        .collect()
}

/// What a user sets on the symmetric pose (`--pose pose.toml`): where the limbs stand
/// (`limbs = "rest"` or `"mean"`, see [`Limbs`]), and a `[joints]` table of bone name to
/// rotation vector `[x, y, z]` in degrees (the convention of [`crate::pose::skinning`]). A joint
/// set on one side only is mirrored onto the other, so the pose stays symmetric; set both sides
/// to make it asymmetric on purpose.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct PoseOverrides {
    /// Where the limbs stand before the joints are set.
    pub limbs: Limbs,
    /// Bone index and rotation vector (radians).
    pub joints: Vec<(usize, DVec3)>,
}

/// The file's layout.
#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct PoseFile {
    #[serde(default)]
    limbs: Limbs,
    #[serde(default)]
    joints: BTreeMap<String, [f64; 3]>,
}

impl PoseOverrides {
    /// Reads `path` for `skeleton`.
    pub fn load(path: &Path, skeleton: &Skeleton) -> Result<Self, InputError> {
        Self::parse(&crate::input::read(path)?, path, skeleton)
    }

    /// Parses the text of a pose file (`path` named in errors).
    pub fn parse(text: &str, path: &Path, skeleton: &Skeleton) -> Result<Self, InputError> {
        let file: PoseFile = toml::from_str(text).map_err(|e| InputError::Syntax {
            path: path.to_path_buf(),
            kind: "pose",
            message: e.message().to_string(),
        })?;
        let mut problems = Vec::new();
        let mut joints = Vec::new();
        for (name, deg) in &file.joints {
            let Some(bone) = skeleton.names.iter().position(|n| n == name) else {
                problems.push(format!(
                    "joints.\"{name}\": no such joint (the joints: {})",
                    skeleton.names.join(", ")
                ));
                continue;
            };
            let v = DVec3::from_array(*deg);
            if !v.is_finite() || v.length() > MAX_OVERRIDE_DEG {
                problems.push(format!(
                    "joints.\"{name}\": {deg:?} is not a rotation of at most {MAX_OVERRIDE_DEG} degrees"
                ));
                continue;
            }
            joints.push((bone, v * std::f64::consts::PI / 180.0));
        }
        crate::input::check(path, if problems.is_empty() { Ok(()) } else { Err(problems) })?;
        Ok(PoseOverrides { limbs: file.limbs, joints })
    }

    /// `theta` with the overrides set (mirrored onto a partner the file does not name).
    pub fn apply(&self, theta: &mut [DVec3], skeleton: &Skeleton) {
        let partner = skeleton.mirror();
        let named = |b: usize| self.joints.iter().any(|&(j, _)| j == b);
        for &(b, angle) in &self.joints {
            theta[b] = angle;
            if partner[b] != b && !named(partner[b]) {
                theta[partner[b]] = mirror(angle);
            }
        }
    }
}

/// The scan re-posed (eq. 3): each vertex moved by the blend of its bones' motions from the
/// fitted pose `from` to the pose `to`, `G_to(l) G_from(l)^-1`, about the fitted shape's rest
/// `joints` and the fitted `translation`.
pub fn repose(
    vertices: &[DVec3],
    weights: &SkinWeights,
    parents: &[Option<usize>],
    joints: &[DVec3],
    from: &[DVec3],
    to: &[DVec3],
    translation: DVec3,
) -> Vec<DVec3> {
    let fitted = skinning::bone_transforms(parents, joints, from, translation);
    let target = skinning::bone_transforms(parents, joints, to, translation);
    let relative: Vec<_> = target.iter().zip(&fitted).map(|(t, f)| *t * f.inverse()).collect();
    skinning::skin(vertices, weights, &relative)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn skeleton() -> Skeleton {
        Skeleton {
            names: ["root", "spine", "arm.L", "arm.R"].map(String::from).to_vec(),
            parents: vec![None, Some(0), Some(1), Some(1)],
        }
    }

    #[test]
    fn a_mirrored_rotation_moves_the_mirror_image_of_a_point() {
        let theta = DVec3::new(0.3, -0.2, 0.5);
        let p = DVec3::new(1.0, 2.0, 3.0);
        let flip = |v: DVec3| DVec3::new(-v.x, v.y, v.z);
        let a = flip(skinning::rotation(theta) * p);
        let b = skinning::rotation(mirror(theta)) * flip(p);
        assert!(a.distance(b) < 1e-12, "{a} vs {b}");
    }

    #[test]
    fn the_symmetric_pose_averages_the_sides_and_straightens_the_midline() {
        let s = skeleton();
        let theta = [
            DVec3::new(0.1, 0.2, 0.3),
            DVec3::new(-0.2, 0.1, -0.1),
            DVec3::new(0.1, -0.4, 0.0),
            DVec3::new(0.3, 0.2, 0.0),
        ];
        let sym = symmetric(&theta, &s, Limbs::Mean);
        assert!(sym[0].distance(DVec3::new(0.1, 0.0, 0.0)) < 1e-12, "{}", sym[0]);
        assert!(sym[1].distance(DVec3::new(-0.2, 0.0, 0.0)) < 1e-12, "{}", sym[1]);
        // Left arm down by 0.4, the right (mirrored) by 0.2: both at 0.3; swung 0.1 and 0.3
        // forward: both 0.2.
        assert!(sym[2].distance(DVec3::new(0.2, -0.3, 0.0)) < 1e-12, "{}", sym[2]);
        assert_eq!(sym[3], mirror(sym[2]));
        // At rest the arms stand as the model's rest but for their mean forward swing, the
        // midline as with the mean.
        let rest = symmetric(&theta, &s, Limbs::Rest);
        assert_eq!(rest[..2], sym[..2]);
        assert_eq!(rest[2..], [DVec3::new(sym[2].x, 0.0, 0.0); 2]);
    }

    #[test]
    fn a_pose_file_sets_named_joints_and_mirrors_one_sided_ones() {
        let s = skeleton();
        let o = PoseOverrides::parse("[joints]\n\"arm.L\" = [0, -30, 0]\n", Path::new("p"), &s)
            .unwrap();
        assert_eq!(o.limbs, Limbs::Rest);
        let mean = PoseOverrides::parse("limbs = \"mean\"\n", Path::new("p"), &s).unwrap();
        assert_eq!((mean.limbs, mean.joints.len()), (Limbs::Mean, 0));
        let mut theta = vec![DVec3::ZERO; 4];
        o.apply(&mut theta, &s);
        assert!((theta[2].y + 30f64.to_radians()).abs() < 1e-12);
        assert_eq!(theta[3], mirror(theta[2]));
        let e = PoseOverrides::parse("[joints]\nelbow = [0, 0, 0]\n", Path::new("p.toml"), &s)
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("p.toml: joints.\"elbow\": no such joint"), "{e}");
        let e = PoseOverrides::parse("[joints]\n\"arm.L\" = [0, 200, 0]\n", Path::new("p"), &s)
            .unwrap_err()
            .to_string();
        assert!(e.contains("at most 180 degrees"), "{e}");
    }

    #[test]
    fn reposing_to_the_fitted_pose_leaves_the_scan_in_place() {
        let s = skeleton();
        let joints = [DVec3::ZERO, DVec3::Z, DVec3::new(1.0, 0.0, 1.0), DVec3::new(-1.0, 0.0, 1.0)];
        let theta = [DVec3::new(0.1, 0.0, 0.2), DVec3::X * 0.3, DVec3::Y * 0.5, DVec3::ZERO];
        let w = SkinWeights::normalised(vec![vec![(2, 0.7), (1, 0.3)]]);
        let v = [DVec3::new(2.0, 0.5, 0.5)];
        let t = DVec3::new(5.0, 0.0, 0.0);
        let same = repose(&v, &w, &s.parents, &joints, &theta, &theta, t);
        assert!(same[0].distance(v[0]) < 1e-12);
    }
}
