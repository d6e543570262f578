//! The arm's measurements (ISO 8559-1, arms hanging): upper-arm girth, wrist girth and arm
//! length, each side.
//!
//! The arm's axis is followed down its horizontal loops (labelled by the segmentation, from
//! the armpit to the fingertip): each loop's centroid lies on the axis, and the axis'
//! direction at a loop is the chord between its neighbours [`AXIS_SPAN_MM`] above and below.
//! Where a rule looks for an extreme (the narrowest wrist), the candidates are compared by the
//! horizontal loop projected along the axis onto the perpendicular plane: for a limb that is
//! locally a tube that *is* the perpendicular section. The girth reported is then cut exactly,
//! by the plane through the axis point perpendicular to the axis: an abducted, bent arm meets
//! a horizontal plane so obliquely that its loop reaches from the forearm into the flat hand
//! (the projection read wrists 6-13 mm short on the generator's customers). An arm raised
//! close to horizontal has no such loops: its measurements are absent.

use super::plane::PlaneLoop;
use crate::body::mesh::Mesh;
use crate::body::regions::Region;
use crate::body::segmented_body::SegmentedBody;
use crate::body::slice::Contour;
use glam::{DVec2, DVec3};
use serde::Serialize;

/// Spacing of the arm's loops (mm).
const STEP_MM: f64 = 4.0;
/// Half the length of axis over which the axis' direction is taken (mm): a few loops, less
/// than the forearm's taper changes over.
const AXIS_SPAN_MM: f64 = 24.0;
/// The upper arm's length (shoulder point to elbow) as a fraction of the stature (Drillis
/// and Contini's segment proportions: 0.186 H).
pub const UPPER_ARM_OF_STATURE: f64 = 0.186;
/// Where the wrist is looked for, as fractions of the stature measured up the axis from the
/// fingertip: the hand is 0.108 H long (Drillis and Contini); the window spans the hand's
/// variation and stops short of the fingers, whose loops are narrower than any wrist.
pub const WRIST_FROM_FINGERTIP: (f64, f64) = (0.08, 0.15);
/// How far below the armpit the upper arm's girth may be taken (mm): the loops just below it
/// still hold the crease's blend into the torso.
const BELOW_ARMPIT_MM: f64 = 20.0;

/// Where an arm measurement was taken: the axis point and direction (down the arm).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ArmSection {
    /// The point on the arm's axis (mm).
    #[serde(rename = "centre_mm")]
    pub centre: DVec3,
    /// The axis' direction there, unit, pointing down the arm.
    pub axis: DVec3,
    /// The tape girth perpendicular to the axis (mm).
    #[serde(rename = "girth_mm")]
    pub girth: f64,
}

/// One arm's measurements.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ArmMeasures {
    /// Upper-arm girth: perpendicular to the axis, midway between the armpit and the elbow
    /// (the axis point [`UPPER_ARM_OF_STATURE`] of the stature from the shoulder point), and
    /// at least [`BELOW_ARMPIT_MM`] below the armpit.
    pub upper_arm: ArmSection,
    /// Wrist girth: the narrowest girth perpendicular to the axis between
    /// [`WRIST_FROM_FINGERTIP`] of the stature above the fingertip.
    pub wrist: ArmSection,
    /// Arm length: from the shoulder point to the elbow's axis point, then down the axis to
    /// the wrist (mm).
    pub length: f64,
}

/// The arm measurements of both sides (`None` for a side whose arm has no horizontal loops
/// below its armpit long enough to hold an upper arm, forearm and hand).
pub fn arms(body: &SegmentedBody) -> [Option<ArmMeasures>; 2] {
    let m = body.landmarks();
    [(Region::LeftArm, &m.left_armhole), (Region::RightArm, &m.right_armhole)].map(
        |(region, armhole)| {
            let loops = arm_loops(body, region, armhole.arm_apart_below());
            measure_arm(body.mesh(), &loops, armhole.shoulder_point, m.height)
        },
    )
}

/// The arm's loops from just below `apart` (where it leaves the torso) down to its end, with
/// their heights.
fn arm_loops(body: &SegmentedBody, region: Region, apart: f64) -> Vec<(f64, Contour)> {
    let zs: Vec<f64> = (1..).map(|k| apart - STEP_MM * k as f64).take_while(|&z| z > 0.0).collect();
    body.sections_of(region, &zs)
        .into_iter()
        .zip(&zs)
        .map_while(|(c, &z)| c.map(|c| (z, c)))
        .collect()
}

/// The tape girth of `body`'s section by the plane through `centre` perpendicular to `axis`:
/// the loop around `centre` (or the one whose centroid is nearest), hulled.
fn girth_across(body: &Mesh, centre: DVec3, axis: DVec3) -> f64 {
    PlaneLoop::around(body, centre, axis).map_or(0.0, |l| l.contour.tape_girth())
}

/// The girth perpendicular to unit `axis` of the horizontal `loop_` at height `z`, through its
/// centroid, estimated by projecting the loop along the axis onto the perpendicular plane.
fn projected_girth(loop_: &Contour, z: f64, axis: DVec3) -> f64 {
    let centre = loop_.centroid().extend(z);
    let u = axis.any_orthonormal_vector();
    let v = axis.cross(u);
    let points = loop_
        .points
        .iter()
        .map(|p| {
            let q = p.extend(z) - centre;
            DVec2::new(q.dot(u), q.dot(v))
        })
        .collect();
    Contour { points }.tape_girth()
}

/// One arm's measurements of `body` from its `loops` (top down) and its `shoulder_point`, on
/// a body `height` tall.
fn measure_arm(
    body: &Mesh,
    loops: &[(f64, Contour)],
    shoulder_point: DVec3,
    height: f64,
) -> Option<ArmMeasures> {
    let centres: Vec<DVec3> = loops.iter().map(|(z, c)| c.centroid().extend(*z)).collect();
    let span = (AXIS_SPAN_MM / STEP_MM).round() as usize;
    let axis = |k: usize| {
        let (a, b) = (k.saturating_sub(span), (k + span).min(centres.len() - 1));
        (centres[b] - centres[a]).normalize_or(DVec3::NEG_Z)
    };
    let section = |k: usize| ArmSection {
        centre: centres[k],
        axis: axis(k),
        girth: girth_across(body, centres[k], axis(k)),
    };
    // Distance along the axis from the top loop, loop by loop.
    let mut along = vec![0.0; centres.len()];
    for k in 1..centres.len() {
        along[k] = along[k - 1] + centres[k].distance(centres[k - 1]);
    }
    let fingertip = *along.last()?;
    let upper_length = UPPER_ARM_OF_STATURE * height;
    let elbow =
        (0..centres.len()).find(|&k| centres[k].distance(shoulder_point) >= upper_length)?;
    let lowest_upper = (0..elbow).find(|&k| loops[0].0 - loops[k].0 >= BELOW_ARMPIT_MM)?;
    let upper = ((elbow / 2).max(lowest_upper)).min(elbow);
    let window =
        (fingertip - WRIST_FROM_FINGERTIP.1 * height, fingertip - WRIST_FROM_FINGERTIP.0 * height);
    let wrist = (elbow..centres.len())
        .filter(|&k| along[k] >= window.0 && along[k] <= window.1)
        .map(|k| (k, projected_girth(&loops[k].1, loops[k].0, axis(k))))
        .min_by(|a, b| a.1.total_cmp(&b.1))?
        .0;
    let length = shoulder_point.distance(centres[elbow]) + (along[wrist] - along[elbow]);
    Some(ArmMeasures { upper_arm: section(upper), wrist: section(wrist), length })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Horizontal loops of a round tube of `radius` along unit `axis` (down), every step.
    fn tube(radius: f64, axis: DVec3, top: DVec3, count: usize) -> Vec<(f64, Contour)> {
        let u = axis.any_orthonormal_vector();
        let v = axis.cross(u);
        (0..count)
            .map(|k| {
                let z = top.z - STEP_MM * k as f64;
                // Where the tube's axis crosses height z, and its circle cut by the plane.
                let centre = top + axis * ((top.z - z) / -axis.z);
                let points = (0..180)
                    .map(|i| {
                        let t = std::f64::consts::TAU * i as f64 / 180.0;
                        let dir = u * t.cos() + v * t.sin();
                        // Along the axis to the horizontal plane through z.
                        let p = centre + dir * radius;
                        let s = (z - p.z) / axis.z;
                        (p + axis * s).truncate()
                    })
                    .collect();
                (z, Contour { points })
            })
            .collect()
    }

    #[test]
    fn an_oblique_tube_reads_its_perpendicular_girth() {
        let axis = DVec3::new(0.3, 0.1, -1.0).normalize();
        let loops = tube(40.0, axis, DVec3::new(200.0, 0.0, 1300.0), 10);
        let (z, c) = &loops[5];
        let girth = projected_girth(c, *z, axis);
        let exact = std::f64::consts::TAU * 40.0;
        // A 180-gon's perimeter is within 0.01% of the circle's.
        assert!((girth - exact).abs() < 0.001 * exact, "{girth} vs {exact}");
        // The horizontal loop itself is longer (an ellipse).
        assert!(c.tape_girth() > exact + 1.0);
    }
}
