//! Did the fit converge? The residual per body region: for each model vertex, its distance to
//! the nearest scan point, and per region (torso, head, each arm, each leg) the median over the
//! region's vertices. A region whose median is above [`MAX_REGION_MEDIAN_MM`] (the torso:
//! [`MAX_TORSO_MEDIAN_MM`]) is not on the scan: a limb matched to the wrong place, or a scan
//! that is no whole body (a sphere, a box, the upper half of a body). The median ignores
//! holes, which leave a minority of a region's vertices far from the scan.

use super::ModelFit;
use crate::pose::body_model::BodyModel;
use glam::DVec3;
use kiddo::{ImmutableKdTree, SquaredEuclidean};
use rayon::prelude::*;

/// The largest median distance of a limb's or the head's model vertices to the scan for a
/// converged fit (mm). Converged fits of MakeHuman scans with 0.7 mm noise and holes stay at
/// 1-3 mm in every region (`tests/pose_symmetry.rs` prints them), the sim generator's bodies
/// (capsule limbs, a paddle hand) at 4-6 mm on the legs and head and 6-10.4 mm on the arms
/// (the demo customer and random seeds 1-5, an arm 15 degrees further out); a limb off by a
/// limb's radius (~40 mm), or a region with no scan at all, is far above.
pub const MAX_REGION_MEDIAN_MM: f64 = 12.0;

/// The same for the torso (mm): its median measures the torso's shape more than its place
/// (the limbs and the head hang from it, and their own limits catch a torso misplaced). A
/// torso outside the model's 15-component shape space stays off by its shape: the sim
/// generator's random customers at 7.6-12.4 mm (seeds 2 and 4, a slim waist of 638 mm: the
/// model's waist 20-29 mm wide of it while the chest's front lies within 3 mm), MakeHuman
/// scans at 1-4. A hopeless input is far above (a box 70 mm, a sphere 361 mm). Re-posing moves
/// the scan, not the model, so a shape the model cannot follow costs the mannequin nothing.
pub const MAX_TORSO_MEDIAN_MM: f64 = 20.0;

/// The limit of a region's median ([`REGIONS`]' first is the torso).
fn limit_of(region: &str) -> f64 {
    if region == REGIONS[0].0 { MAX_TORSO_MEDIAN_MM } else { MAX_REGION_MEDIAN_MM }
}

/// The body regions, and the bones whose vertices they hold (by name prefix and side). The
/// hands are not judged: the mannequin has none, customers hold them every way (a fist, the
/// fingers spread) and scanners lose fingers, and MakeHuman's densely meshed hand would
/// outvote the rest of its arm in a median over vertices.
pub const REGIONS: [(&str, &[&str]); 6] = [
    ("torso", &["root", "spine", "clavicle"]),
    ("head", &["neck", "head"]),
    ("left arm", &["upperarm01.L", "lowerarm01.L"]),
    ("right arm", &["upperarm01.R", "lowerarm01.R"]),
    ("left leg", &["upperleg01.L", "lowerleg01.L", "foot.L"]),
    ("right leg", &["upperleg01.R", "lowerleg01.R", "foot.R"]),
];

/// One region's residual.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct RegionResidual {
    /// The region's name ([`REGIONS`]).
    pub region: &'static str,
    /// The median distance of its model vertices to the scan (mm).
    pub median_mm: f64,
    /// The 90th percentile (mm): holes show here.
    pub p90_mm: f64,
    /// The largest median of a converged fit in this region (mm).
    pub max_median_mm: f64,
}

/// Why a fit is not to be trusted.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error(
    "the body model did not converge onto the scan: the {region} is {median_mm:.0} mm from it \
     (median; at most {max_mm} mm) - is this a whole standing body?"
)]
pub struct NotConverged {
    /// The worst region.
    pub region: &'static str,
    /// Its median distance (mm).
    pub median_mm: f64,
    /// Its limit (mm).
    pub max_mm: f64,
}

/// The region of each of the model's bones (`None` for a bone no region lists).
fn bone_regions(model: &BodyModel) -> Vec<Option<usize>> {
    let names = &model.skeleton.names;
    names
        .iter()
        .map(|n| REGIONS.iter().position(|(_, bones)| bones.iter().any(|b| n.starts_with(b))))
        .collect()
}

/// The residual per region of `fit` against the scan `points`.
pub fn residuals(model: &BodyModel, fit: &ModelFit, points: &[DVec3]) -> Vec<RegionResidual> {
    let coords: Vec<[f64; 3]> = points.iter().map(|p| p.to_array()).collect();
    let tree: ImmutableKdTree<f64, 3> = ImmutableKdTree::new_from_slice(&coords);
    let vertices = fit.vertices(model);
    let distance: Vec<f64> = vertices
        .par_iter()
        .map(|v| tree.nearest_one::<SquaredEuclidean>(&v.to_array()).distance.sqrt())
        .collect();
    let regions = bone_regions(model);
    let mut per_region: Vec<Vec<f64>> = vec![Vec::new(); REGIONS.len()];
    for (v, d) in distance.iter().enumerate() {
        let strongest = model.weights.of(v).max_by(|a, b| a.1.total_cmp(&b.1));
        if let Some(r) = strongest.and_then(|(bone, _)| regions[bone]) {
            per_region[r].push(*d);
        }
    }
    REGIONS
        .iter()
        .zip(per_region)
        .map(|((region, _), mut d)| {
            d.sort_by(f64::total_cmp);
            let at = |q: f64| d.get(((d.len() as f64 - 1.0) * q).round() as usize).copied();
            RegionResidual {
                region,
                median_mm: at(0.5).unwrap_or(f64::INFINITY),
                p90_mm: at(0.9).unwrap_or(f64::INFINITY),
                max_median_mm: limit_of(region),
            }
        })
        .collect()
}

/// The verdict on `residuals`: the region furthest over its limit, if any.
pub fn verdict(residuals: &[RegionResidual]) -> Result<(), NotConverged> {
    let over = |r: &RegionResidual| r.median_mm / r.max_median_mm;
    let worst = residuals.iter().max_by(|a, b| over(a).total_cmp(&over(b)));
    match worst {
        Some(r) if r.median_mm.is_nan() || r.median_mm > r.max_median_mm => {
            Err(NotConverged { region: r.region, median_mm: r.median_mm, max_mm: r.max_median_mm })
        }
        _ => Ok(()),
    }
}
