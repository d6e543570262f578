//! Joint limits (eq. 4's pose regulariser): the range of each bone's rotation, relative to its
//! parent in the model's rest A-pose, that a standing person can reach. The fit pays for
//! leaving it ([`super::priors`]), so that a fit never bends a knee backwards or lifts a
//! clavicle to the ear to match a hole.
//!
//! Ranges are the active ranges of motion of the American Academy of Orthopaedic Surgeons
//! ("Joint Motion: Method of Measuring and Recording", AAOS 1965; Greene & Heckman, "The
//! Clinical Measurement of Joint Motion", AAOS 1994), the spine's per-region totals of White &
//! Panjabi ("Clinical Biomechanics of the Spine", 2nd ed. 1990, table 2-9: lumbar and thoracic
//! lateral bend about 30 degrees each side in all, axial rotation about 35 thoracic and 10
//! lumbar) shared among the model's four spine bones, and for the sternoclavicular joint
//! Ludewig et al. 2009 (J Bone Joint Surg Am 91:378, clavicle elevation up to about 30 degrees,
//! retraction/protraction about 30). Each is widened by [`MARGIN_DEG`] because the model's rest
//! pose is an A-pose, not the anatomical zero.
//!
//! Axes are the rest frame's ([`crate::pose::skinning`]): X the subject's left, Y backwards, Z up.
//! For a bone hanging down (arm, leg) a turn about +X swings it backwards, about +Y towards the
//! subject's right (the left limb in, the right limb out); for a bone pointing up (spine, neck)
//! a turn about +X bends it forwards, about +Y to the subject's left. Ranges are the left
//! side's; the right side's are their mirror images (`y` and `z` negated, see
//! [`crate::pose::pose_symmetry::mirror`]).

use crate::pose::body_model::Skeleton;
use glam::DVec3;

/// How far the ranges below are widened (degrees): the MakeHuman rest pose's arms hang about
/// 45 degrees out and its elbows and knees are slightly bent, so the anatomical zero is a few
/// degrees off the model's.
pub const MARGIN_DEG: f64 = 5.0;

/// Per bone (left side and midline), the lowest and highest turn about X, Y and Z (degrees).
const RANGES_DEG: [(&str, [(f64, f64); 3]); 20] = [
    // Each spine bone a quarter of the lumbar + thoracic totals (flexion 60 + 45, extension
    // 25 + 25, lateral bend 30 + 30, rotation 10 + 35).
    ("spine04", [(-12.0, 26.0), (-15.0, 15.0), (-11.0, 11.0)]),
    ("spine03", [(-12.0, 26.0), (-15.0, 15.0), (-11.0, 11.0)]),
    ("spine02", [(-12.0, 26.0), (-15.0, 15.0), (-11.0, 11.0)]),
    ("spine01", [(-12.0, 26.0), (-15.0, 15.0), (-11.0, 11.0)]),
    // Cervical spine (flexion 45, extension 45, lateral bend 45, rotation 60) halved between
    // the neck and the head.
    ("neck01", [(-23.0, 23.0), (-23.0, 23.0), (-30.0, 30.0)]),
    ("head", [(-23.0, 23.0), (-23.0, 23.0), (-30.0, 30.0)]),
    // Sternoclavicular: axial rotation 30 about its length (X), elevation 30 / depression 10
    // (-Y raises the left one), protraction and retraction 30 (Z).
    ("clavicle.L", [(-30.0, 30.0), (-30.0, 10.0), (-30.0, 30.0)]),
    // Shoulder: flexion 180 / extension 60, abduction to 180 from the A-pose's 45 out and
    // adduction to the side, rotation 90.
    ("upperarm01.L", [(-180.0, 60.0), (-135.0, 45.0), (-90.0, 90.0)]),
    // Elbow: flexion 150 (forwards, -X), extension back to a straight arm; the forearm's 90 of
    // pronation and supination about its length, which in the A-pose lies between Y and Z.
    // The model's rest elbow is already bent 46.6 degrees about an axis whose X share is 0.76
    // (the mean body's joints, upperarm01 -> lowerarm01 -> wrist), so straightening it is
    // +35 about X: customers scan with nearly straight arms (the sim generator's A-pose: 10).
    ("lowerarm01.L", [(-150.0, 35.0), (-90.0, 90.0), (-90.0, 90.0)]),
    // Wrist: flexion 80 / extension 70, radial 20 / ulnar 30 deviation, no twist of its own.
    ("wrist.L", [(-80.0, 70.0), (-30.0, 30.0), (-20.0, 20.0)]),
    // Hip: flexion 120 (forwards, -X) / extension 30, abduction 45 (-Y) / adduction 30,
    // rotation 45.
    ("upperleg01.L", [(-120.0, 30.0), (-45.0, 30.0), (-45.0, 45.0)]),
    // Knee: flexion 135 (backwards, +X), no hyperextension, no sideways bend, 30 of rotation.
    ("lowerleg01.L", [(0.0, 135.0), (0.0, 0.0), (-30.0, 30.0)]),
    // Ankle: plantar flexion 50 (+X) / dorsiflexion 20, inversion 35 / eversion 15 about the
    // foot's length (Y), 20 of abduction and adduction.
    ("foot.L", [(-20.0, 50.0), (-15.0, 35.0), (-20.0, 20.0)]),
    // The right side: mirrors of the left ones, filled in by [`JointLimits::new`].
    ("clavicle.R", [(0.0, 0.0); 3]),
    ("upperarm01.R", [(0.0, 0.0); 3]),
    ("lowerarm01.R", [(0.0, 0.0); 3]),
    ("wrist.R", [(0.0, 0.0); 3]),
    ("upperleg01.R", [(0.0, 0.0); 3]),
    ("lowerleg01.R", [(0.0, 0.0); 3]),
    ("foot.R", [(0.0, 0.0); 3]),
];

/// Each bone's allowed rotation vector, a box per axis (radians); the root is free.
#[derive(Debug, Clone, PartialEq)]
pub struct JointLimits {
    /// Per bone, the lowest and the highest rotation vector (`None`: free).
    pub ranges: Vec<Option<(DVec3, DVec3)>>,
}

impl JointLimits {
    /// The limits of `skeleton`'s bones (bones the table does not name are free).
    pub fn new(skeleton: &Skeleton) -> Self {
        let partner = skeleton.mirror();
        let margin = MARGIN_DEG.to_radians();
        let of = |name: &str| -> Option<(DVec3, DVec3)> {
            let (_, axes) = RANGES_DEG.iter().find(|(n, _)| *n == name)?;
            let lo = DVec3::new(axes[0].0, axes[1].0, axes[2].0);
            let hi = DVec3::new(axes[0].1, axes[1].1, axes[2].1);
            Some((
                lo * std::f64::consts::PI / 180.0 - margin,
                hi * std::f64::consts::PI / 180.0 + margin,
            ))
        };
        let ranges = (0..skeleton.names.len())
            .map(|b| {
                let name = &skeleton.names[b];
                if !name.ends_with(".R") {
                    return of(name);
                }
                // The mirror of [lo, hi] on Y and Z is [-hi, -lo].
                let (lo, hi) = of(&skeleton.names[partner[b]])?;
                Some((DVec3::new(lo.x, -hi.y, -hi.z), DVec3::new(hi.x, -lo.y, -lo.z)))
            })
            .collect();
        JointLimits { ranges }
    }

    /// How far `theta` lies outside bone `b`'s range, per axis (zero inside).
    pub fn excess(&self, b: usize, theta: DVec3) -> DVec3 {
        self.ranges[b].map_or(DVec3::ZERO, |(lo, hi)| theta - theta.clamp(lo, hi))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::pose::body_model::BodyModel;
    use crate::pose::pose_symmetry::mirror;

    #[test]
    fn the_right_side_is_the_mirror_of_the_left_and_the_root_is_free() {
        let model = BodyModel::builtin();
        let skeleton = &model.skeleton;
        let limits = JointLimits::new(skeleton);
        let partner = skeleton.mirror();
        assert_eq!(limits.ranges[0], None);
        for (b, name) in skeleton.names.iter().enumerate().skip(1) {
            assert!(limits.ranges[b].is_some(), "{name} has no range");
            // A pose inside the left range mirrors to one inside the right range.
            let (lo, hi) = limits.ranges[b].unwrap();
            for t in [0.1, 0.5, 0.9] {
                let inside = lo + (hi - lo) * t;
                assert_eq!(limits.excess(b, inside), DVec3::ZERO, "{name}");
                assert_eq!(limits.excess(partner[b], mirror(inside)), DVec3::ZERO, "{name}");
            }
        }
        // A knee bent forwards (hyperextended) by 20 degrees is 15 outside (5 of margin).
        let knee = skeleton.names.iter().position(|n| n == "lowerleg01.L").unwrap();
        let excess = limits.excess(knee, DVec3::X * -20f64.to_radians());
        assert!((excess.x.to_degrees() + 15.0).abs() < 1e-9, "{excess}");
    }
}
