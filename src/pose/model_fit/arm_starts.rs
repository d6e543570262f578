//! Several starts for the arms: landmark-free fits are known to settle with an arm matched to
//! the torso beside it. Before the limbs are freed, each upper arm tries a range of
//! abductions about the rest frame's front-to-back axis and keeps the one that lies closest to
//! the scan both ways ([`RobustDistance`]: an arm far from the scan, or a part of the scan no
//! arm covers, is charged in full). Only the arm moves between its starts, so the rest of the
//! model is measured once per arm.

use super::correspondences::ScanCloud;
use super::correspondences::robust_distance::RobustDistance;
use super::params::{Params, PreparedModel, vertex_normals};
use glam::{DQuat, DVec3};

/// The abductions tried for each arm (degrees outwards from the current angle): the scanning
/// poses the paper and issue 15 cover put an arm between the A-pose and 60 degrees further out;
/// issue 35's hard stances hang an arm 0-5 degrees from the body (the model's rest arm is 40
/// out).
pub const ARM_STARTS_DEG: [f64; 7] = [-35.0, -15.0, 0.0, 15.0, 30.0, 45.0, 60.0];

/// The upper arms and the sign that turns each outwards about +Y (the skinning convention: a
/// positive turn about +Y brings the left arm down).
const ARMS: [(&str, f64); 2] = [("upperarm01.L", -1.0), ("upperarm01.R", 1.0)];

/// `params` with each arm at its best start.
pub fn best(prep: &PreparedModel, scan: &ScanCloud, mut params: Params, sigma: f64) -> Params {
    for (name, outwards) in ARMS {
        let Some(bone) = prep.model.skeleton.names.iter().position(|n| n == name) else {
            continue;
        };
        let base = params.theta[bone];
        let mut best = (f64::INFINITY, base);
        let mut distance = RobustDistance::new(scan, sigma, moved_by(prep, bone));
        for deg in ARM_STARTS_DEG {
            let turn = DQuat::from_axis_angle(DVec3::Y, outwards * deg.to_radians());
            let theta = (turn * DQuat::from_scaled_axis(base)).to_scaled_axis();
            params.theta[bone] = theta;
            let posed = prep.pose(&params);
            let normals = vertex_normals(&posed.vertices, &prep.model.triangles);
            let cost = distance.of(&posed.vertices, &normals);
            if cost < best.0 {
                best = (cost, theta);
            }
        }
        params.theta[bone] = best.1;
    }
    params
}

/// Per model vertex, whether turning `bone` can move it or change its normal: the vertices
/// weighted to the bone or a bone below it, and every corner of a triangle that holds one.
fn moved_by(prep: &PreparedModel, bone: usize) -> Vec<bool> {
    let model = prep.model;
    let below = &prep.descends[bone];
    let mut moved: Vec<bool> =
        (0..model.mean.len()).map(|v| model.weights.of(v).any(|(l, _)| below[l])).collect();
    let touched: Vec<&[u32; 3]> =
        model.triangles.iter().filter(|t| t.iter().any(|&v| moved[v as usize])).collect();
    touched.into_iter().flatten().for_each(|&v| moved[v as usize] = true);
    moved
}
