//! Cutting the torso and legs into layers and making each symmetric.

use super::side_heights::SideHeights;
use super::{Layer, MannequinError, MannequinOptions};
use crate::body::regions::{Region, largest_with};
use crate::body::segmented_body::SegmentedBody;
use crate::body::slice::Contour;
use crate::shape::symmetry::{axial, bilateral};
use glam::DVec2;
use rayon::prelude::*;

/// How far inside the crotch the first torso and last leg layers stay (mm): exactly at the
/// crotch the torso loop is just forming.
const CROTCH_CLEARANCE_MM: f64 = 1.0;

/// The legs' mesh rings are about this far apart next to the crotch (mm): the torso's layers
/// are 6-8 mm apart there at the paper's 100. At 2 mm (the height of the band joining the legs
/// to the torso) the rings sampled the thin inner-back corner of the leg sections just below
/// the MakeHuman body's crotch, and neighbouring rings crossed there.
const FINE_NEXT_MM: f64 = 4.0;

/// Within this distance below the crotch (mm) the legs' mesh has rings between their layers,
/// spaced from [`FINE_NEXT_MM`] at the crotch growing linearly to the layers' own spacing
/// (13-15 mm at the paper's 50 layers). The gluteal fold under the buttocks reaches 75 mm
/// below the crotch on the generator's bodies (random-2); sampled by the leg layers alone its
/// turn fell on single rings, creased 8-13 degrees: a shaded line across the back of the
/// thighs; and the legs' coarse rings met the torso's finer ones with a kink.
const FINE_DEPTH_MM: f64 = 100.0;

/// The heights of the legs' mesh rings among their layers at `layer_z` (increasing), each with
/// whether it is a layer: the layers, and each interval between two of them whose middle lies
/// within [`FINE_DEPTH_MM`] of the crotch at `crotch` split evenly into parts about as high as
/// the spacing wanted there (see [`FINE_DEPTH_MM`]). The rings between layers are the mesh's
/// only, as the shoulder cap's are: the layers (`profiles.json`) are the paper's.
fn mesh_rings(layer_z: &[f64], crotch: f64) -> Vec<(f64, bool)> {
    let mut rings = Vec::with_capacity(layer_z.len());
    for pair in layer_z.windows(2) {
        let (lo, hi) = (pair[0], pair[1]);
        let depth = (0.5 * (lo + hi) - crotch).abs();
        let wanted = FINE_NEXT_MM + (hi - lo - FINE_NEXT_MM).max(0.0) * depth / FINE_DEPTH_MM;
        let parts = if depth < FINE_DEPTH_MM { ((hi - lo) / wanted).ceil() as usize } else { 1 };
        rings.push((lo, true));
        rings.extend((1..parts).map(|k| (lo + (hi - lo) * k as f64 / parts as f64, false)));
    }
    rings.push((layer_z[layer_z.len() - 1], true));
    rings
}

/// `count` heights evenly spaced from `lo` to `hi` inclusive.
fn spaced(lo: f64, hi: f64, count: usize) -> Vec<f64> {
    (0..count).map(|k| lo + (hi - lo) * k as f64 / (count - 1) as f64).collect()
}

/// A layer of `points` about `centre` at height `z`, made from the section `input`.
pub(super) fn layer(
    region: Region,
    z: f64,
    centre: DVec2,
    points: Vec<DVec2>,
    input: &Contour,
) -> Layer {
    let ring = Contour { points };
    Layer {
        region,
        z,
        centre: centre.to_array(),
        input_tape_girth: input.tape_girth(),
        input_contour_length: input.perimeter(),
        tape_girth: ring.tape_girth(),
        contour_length: ring.perimeter(),
        points: ring.points,
    }
}

/// The symmetric layers of a body, on one symmetry plane.
pub(super) struct SymmetricLayers {
    pub axis: f64,
    pub torso: Vec<Layer>,
    /// The legs' mesh rings, bottom to top: their layers and the rings between them near the
    /// crotch ([`mesh_rings`]).
    pub left_leg: Vec<Layer>,
    pub right_leg: Vec<Layer>,
    /// Whether each of the legs' rings is one of their layers.
    pub is_layer: Vec<bool>,
}

/// The symmetry axis and the symmetric torso, left-leg and right-leg layers; the torso layers
/// nearest to `keep` heights (the measurement levels) are moved onto them.
pub(super) fn symmetric_layers(
    body: &SegmentedBody,
    keep: &[f64],
    o: &MannequinOptions,
) -> Result<SymmetricLayers, MannequinError> {
    let m = body.landmarks();
    let mut torso_z = spaced(m.crotch + CROTCH_CLEARANCE_MM, m.neck, o.torso_layers);
    let inner = 1..torso_z.len() - 1;
    for &z in keep {
        let nearest = inner
            .clone()
            .min_by(|&a, &b| (torso_z[a] - z).abs().total_cmp(&(torso_z[b] - z).abs()));
        if let Some(k) = nearest.filter(|&k| z > torso_z[k - 1] && z < torso_z[k + 1]) {
            torso_z[k] = z;
        }
    }
    let (leg_z, is_layer): (Vec<f64>, Vec<bool>) =
        mesh_rings(&spaced(m.ankle, m.crotch - CROTCH_CLEARANCE_MM, o.leg_layers), m.crotch)
            .into_iter()
            .unzip();

    // Torso sections, with the arms cut off above the armpits: at each layer's height (its
    // girth, and the symmetry plane), and where its halves are taken from.
    let missing = |z| MannequinError::MissingLoop { region: Region::Torso, z };
    let cut = |heights: &[f64]| -> Result<Vec<Contour>, MannequinError> {
        let found = heights.iter().zip(body.torso_sections(heights));
        found.map(|(&z, c)| c.ok_or(missing(z))).collect()
    };
    let torso_sections = cut(&torso_z)?;
    let sides = SideHeights::of(m);
    let side_z: Vec<f64> = torso_z.iter().flat_map(|&z| sides.at(z)).collect();
    let side_sections = cut(&side_z)?;
    let mut centres: Vec<f64> = torso_sections.iter().map(|c| c.bbox_centre().x).collect();
    centres.sort_by(f64::total_cmp);
    let axis = centres[centres.len() / 2];

    // The layers are independent: made in parallel, the first failure (in layer order) kept.
    let torso: Vec<Result<Layer, MannequinError>> = torso_z
        .par_iter()
        .zip(&torso_sections)
        .zip(side_sections.par_chunks_exact(2))
        .map(|((&z, c), halves)| {
            let (left, right) = (&halves[0], &halves[1]);
            let girth = o.preserve.girth(c);
            let ring = axial::symmetrize_halves(left, right, axis, o.rays, o.preserve, girth)?;
            Ok(layer(Region::Torso, z, ring.centre, ring.points, c))
        })
        .collect();
    let torso = torso.into_iter().collect::<Result<Vec<_>, _>>()?;

    let legs: Vec<Result<[Layer; 2], MannequinError>> = body
        .sections(&leg_z)
        .par_iter()
        .map(|s| {
            let labels = body.regions().label(s);
            let find = |region| {
                largest_with(s, &labels, region)
                    .ok_or(MannequinError::MissingLoop { region, z: s.height })
            };
            let (l, r) = (find(Region::LeftLeg)?, find(Region::RightLeg)?);
            let [lr, rr] = bilateral::symmetrize(l, r, axis, o.rays, o.preserve)?;
            Ok([
                layer(Region::LeftLeg, s.height, lr.centre, lr.points, l),
                layer(Region::RightLeg, s.height, rr.centre, rr.points, r),
            ])
        })
        .collect();
    let mut left_leg = Vec::with_capacity(leg_z.len());
    let mut right_leg = Vec::with_capacity(leg_z.len());
    for [l, r] in legs.into_iter().collect::<Result<Vec<_>, _>>()? {
        left_leg.push(l);
        right_leg.push(r);
    }
    Ok(SymmetricLayers { axis, torso, left_leg, right_leg, is_layer })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_legs_mesh_rings_keep_every_layer_and_are_finer_towards_the_crotch() {
        // The paper's 50 leg layers from the ankle (100 mm) to just below a crotch at 800 mm.
        let crotch = 800.0;
        let layer_z = spaced(100.0, crotch - CROTCH_CLEARANCE_MM, 50);
        let rings = mesh_rings(&layer_z, crotch);
        let kept: Vec<f64> = rings.iter().filter(|(_, l)| *l).map(|(z, _)| *z).collect();
        assert_eq!(kept, layer_z, "the layers are the rings flagged as layers, in order");
        let gaps: Vec<(f64, f64)> =
            rings.windows(2).map(|w| (crotch - 0.5 * (w[0].0 + w[1].0), w[1].0 - w[0].0)).collect();
        assert!(gaps.iter().all(|(_, g)| *g > 0.0), "rings increase");
        let layer_gap = layer_z[1] - layer_z[0];
        for (depth, gap) in gaps {
            if depth > FINE_DEPTH_MM + layer_gap {
                let one = (gap - layer_gap).abs() < 1e-9;
                assert!(one, "a ring between layers {depth} mm below the crotch");
            } else {
                let wanted = FINE_NEXT_MM + (layer_gap - FINE_NEXT_MM) * depth / FINE_DEPTH_MM;
                assert!(gap <= wanted + 0.5 * layer_gap, "{gap} mm apart {depth} mm below");
            }
        }
        let top = rings.len() - 1;
        assert!(rings[top].0 - rings[top - 1].0 < 1.25 * FINE_NEXT_MM, "finest at the crotch");
    }
}
