//! Angles of the skeleton in the frontal plane, as the pose tests state the truth and read
//! the fit: shared by `pose_symmetry` and `pose_symmetry_cases`.

use glam::DVec3;

/// A limb's angle from straight down in the frontal plane (degrees, outwards positive on
/// both sides), from its upper joint to its lower one.
pub fn abduction(upper: DVec3, lower: DVec3) -> f64 {
    let d = lower - upper;
    d.x.abs().atan2(-d.z).to_degrees()
}

/// The clavicle's elevation: its direction's angle above the horizontal in the frontal plane
/// (degrees).
pub fn elevation(inner: DVec3, outer: DVec3) -> f64 {
    let d = outer - inner;
    d.z.atan2(d.x.abs()).to_degrees()
}
