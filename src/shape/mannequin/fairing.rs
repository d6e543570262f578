//! Fairing the symmetric layers across heights: the scanner's noise is not the customer's body.
//!
//! Each layer is sampled from its own section, so what is left of the scanner's noise after
//! denoising ([`crate::body::mesh::Mesh::taubin_smooth`]) differs from one layer to the next: on the
//! demo customer's scan a ray's point jumped 0.63 mm RMS (second difference) from layer to
//! layer mid-torso, where the body's own curvature accounts for about 0.1 mm. Between two
//! rings the mesh is flat, so the surface looked lumpy and every layer showed as a shaded
//! horizontal band.
//!
//! So each ray's point becomes the value, at its own height, of the line fitted to that ray's
//! points on the layers around it, weighted by a Gaussian of the height difference
//! ([`SIGMA_MM`], [`local_line`]), moved at most [`MAX_MOVE_MM`]; the layers' centres are
//! faired with them. The layer is then made mirror-symmetric again (eq. 7) and scaled back to
//! the girth it had (eq. 8 and 12), so every girth is kept exactly. On the demo the jump falls
//! to 0.33 mm. Points on the arm plates (at or beyond a plate, less [`PLATE_BAND_MM`], between
//! the armpit and the shoulder point) are neither moved nor used: the plates are cut flat
//! ([`super::arm_plates`]), not averaged. The shoulder cap's bent rings
//! ([`super::shoulder_cap`]) are faired the same way where they are level.

use super::Layer;
use crate::body::regions::Armhole;
use crate::body::slice::Contour;
use crate::shape::symmetry::{Preserve, rescale};
use glam::{DVec2, DVec3};

/// The Gaussian's deviation over height (mm). The torso's layers are 6-8 mm apart at the
/// paper's 100, so a layer takes 0.5-0.6 of its neighbours' weight and a tenth of the next
/// ones': the layer-to-layer noise falls by about 40 %, while a feature as tall as the bust's
/// underside (40-60 mm) keeps its shape. The legs' layers (13-15 mm apart at the paper's 50)
/// barely take from each other, except at the crotch, where the mesh's rings are finer.
const SIGMA_MM: f64 = 6.0;

/// Layers farther apart than this many deviations do not take from each other (weight below
/// 1.2 %).
const REACH_SIGMAS: f64 = 3.0;

/// The most a point is moved (mm, before the girth is given back): the noise left after
/// denoising is a few tenths of a millimetre (about 0.25 mm RMS per layer on the demo
/// customer's scan), while the body's own folds (under the bust, at the navel, the gluteal
/// cleft) would be rounded off by several millimetres; on a clean body (MakeHuman's) the
/// torso stays within 2 mm of the input surface.
const MAX_MOVE_MM: f64 = 1.0;

/// A point this close to an arm plate (mm), or beyond it, is on the plate: the averaged chord
/// of an asymmetric body strays from the mannequin's own plate by about a millimetre. The
/// plates' rims lay a side this close on its plate ([`super::arm_plates`]).
pub(super) const PLATE_BAND_MM: f64 = 2.0;

/// Fairs `layers` (bottom to top, one region, each with the same number of rays) in place
/// (see the module docs); `fixed(k, p)`: point `p` of layer `k` is neither moved nor used
/// (on an arm plate, [`on_plates`]). `torso`: the rings are torso rings, mirror images of
/// themselves (eq. 7 is applied again); the legs' rings are mirrored by the other leg's,
/// faired alike.
pub(super) fn fair(
    layers: &mut [Layer],
    fixed: &dyn Fn(usize, DVec2) -> bool,
    preserve: Preserve,
    torso: bool,
) {
    let Some(rays) = layers.first().map(|l| l.points.len()) else { return };
    if layers.iter().any(|l| l.points.len() != rays) {
        return;
    }
    let centre = |l: &Layer| DVec2::from(l.centre);
    let radii: Vec<Vec<f64>> = layers
        .iter()
        .map(|l| l.points.iter().map(|p| (*p - centre(l)).length()).collect())
        .collect();
    let fixed_at: Vec<Vec<bool>> = layers
        .iter()
        .enumerate()
        .map(|(k, l)| l.points.iter().map(|&p| fixed(k, p)).collect())
        .collect();
    let heights: Vec<f64> = layers.iter().map(|l| l.z).collect();
    let reach = REACH_SIGMAS * SIGMA_MM;
    let centres: Vec<DVec2> = layers.iter().map(centre).collect();
    for (k, layer) in layers.iter_mut().enumerate() {
        let girth = preserve.girth(&Contour { points: layer.points.clone() });
        let near: Vec<(usize, f64)> = heights
            .iter()
            .enumerate()
            .map(|(j, z)| (j, (z - layer.z).abs()))
            .filter(|&(_, dz)| dz <= reach)
            .map(|(j, dz)| (j, (-0.5 * (dz / SIGMA_MM).powi(2)).exp()))
            .collect();
        let total: f64 = near.iter().map(|(_, w)| w).sum();
        let c = near.iter().map(|&(j, w)| centres[j] * w).sum::<DVec2>() / total;
        for (i, p) in layer.points.iter_mut().enumerate() {
            if fixed_at[k][i] {
                continue;
            }
            // Every layer's point on ray i, seen from the new centre along the ray: the
            // centres (the sections' box centres, eq. 5) jitter too, by 0.4 mm front to back.
            let u = (*p - centres[k]).normalize_or_zero();
            let samples = near
                .iter()
                .filter(|&&(j, _)| !fixed_at[j][i])
                .map(|&(j, w)| (heights[j] - heights[k], radii[j][i] + (centres[j] - c).dot(u), w));
            // Seen from the new centre, the point itself lies at `own` along the ray.
            let own = radii[k][i] + (centres[k] - c).dot(u);
            let faired = own + (local_line(samples) - own).clamp(-MAX_MOVE_MM, MAX_MOVE_MM);
            *p = c + u * faired;
        }
        if torso {
            // Point j's mirror image is point `rays - 1 - j` (the rays on the symmetry line
            // are not in a torso ring): eq. 7 again, against points fixed on one side only.
            let mirror = |p: DVec2| DVec2::new(2.0 * c.x - p.x, p.y);
            let mirrored: Vec<DVec2> = layer.points.iter().rev().map(|&p| mirror(p)).collect();
            for (p, m) in layer.points.iter_mut().zip(mirrored) {
                *p = 0.5 * (*p + m);
            }
        }
        layer.centre = c.to_array();
        rescale(&mut layer.points, c, preserve, girth);
        let ring = Contour { points: std::mem::take(&mut layer.points) };
        layer.tape_girth = ring.tape_girth();
        layer.contour_length = ring.perimeter();
        layer.points = ring.points;
    }
}

/// The value at 0 of the line fitted by weighted least squares to `(x, y, weight)` samples:
/// the weighted mean where the samples lie evenly on both sides, and no pull towards the
/// inside at the first and last layers, where they lie on one side only (a plain mean there
/// drew the legs' top rings in by the thighs' slope, a crease at the crotch). The mean where
/// the samples do not determine a line.
fn local_line(samples: impl Iterator<Item = (f64, f64, f64)>) -> f64 {
    let [mut w, mut x, mut y, mut xx, mut xy] = [0.0; 5];
    for (xi, yi, wi) in samples {
        w += wi;
        x += wi * xi;
        y += wi * yi;
        xx += wi * xi * xi;
        xy += wi * xi * yi;
    }
    let det = w * xx - x * x;
    if det > DEGENERATE * w * xx { (xx * y - x * xy) / det } else { y / w }
}

/// A line fit is degenerate when its determinant is below this share of `w * xx`: the
/// samples all at one height (a single layer).
const DEGENERATE: f64 = 1e-9;

/// Whether `p` at height `z` is on one of `plates` (see [`PLATE_BAND_MM`]).
pub(super) fn on_plates(plates: &[&Armhole], p: DVec2, z: f64) -> bool {
    plates.iter().any(|plate| on(plate, p, z))
}

/// Whether `p` at height `z` is on `plate` (see [`PLATE_BAND_MM`]).
fn on(plate: &Armhole, p: DVec2, z: f64) -> bool {
    let within = z >= plate.armpit.z && z <= plate.shoulder_point.z;
    within && plate.normal.dot(DVec3::new(p.x, p.y, z) - plate.armpit) >= -PLATE_BAND_MM
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::body::regions::Region;
    use crate::shape::symmetry::rays::direction;

    const RAYS: usize = 360;
    const SPACING_MM: f64 = 7.0;

    /// A deterministic pseudo-noise in [-1, 1].
    fn noise(k: usize) -> f64 {
        ((k * 7919 + 13) % 2001) as f64 / 1000.0 - 1.0
    }

    /// Torso-like rings (the rays on the symmetry line left out), mirror-symmetric about
    /// x = 0: radius `radius(z, ray)`, the centre's y jittering by `jitter` mm.
    fn rings(layers: usize, jitter: f64, radius: impl Fn(f64, usize) -> f64) -> Vec<Layer> {
        (0..layers)
            .map(|k| {
                let z = 1000.0 + SPACING_MM * k as f64;
                let centre = DVec2::new(0.0, jitter * noise(k));
                let points: Vec<DVec2> = (1..RAYS)
                    .filter(|&i| i != RAYS / 2)
                    .map(|i| centre + direction(i, RAYS) * radius(z, i.min(RAYS - i)))
                    .collect();
                let ring = Contour { points };
                Layer {
                    region: Region::Torso,
                    z,
                    centre: centre.to_array(),
                    input_tape_girth: ring.tape_girth(),
                    input_contour_length: ring.perimeter(),
                    tape_girth: ring.tape_girth(),
                    contour_length: ring.perimeter(),
                    points: ring.points,
                }
            })
            .collect()
    }

    /// RMS of the points' second difference from layer to layer (mm), inner layers.
    fn roughness(layers: &[Layer]) -> f64 {
        let mut sum = 0.0;
        let mut count = 0;
        for w in layers.windows(3) {
            for i in 0..w[0].points.len() {
                sum += (w[0].points[i] - 2.0 * w[1].points[i] + w[2].points[i]).length_squared();
                count += 1;
            }
        }
        (sum / f64::from(count)).sqrt()
    }

    #[test]
    fn layer_to_layer_noise_falls_and_every_girth_and_mirror_partner_is_kept() {
        // A 150 mm cylinder with 0.3 mm of noise per layer and ray and 0.4 mm of centre jitter.
        let noisy = rings(30, 0.4, |z, i| 150.0 + 0.3 * noise(i * 31 + z as usize));
        for preserve in Preserve::ALL {
            let mut faired = noisy.clone();
            fair(&mut faired, &|_, _| false, preserve, true);
            let (before, after) = (roughness(&noisy), roughness(&faired));
            assert!(after < 0.6 * before, "{preserve:?}: {before:.3} -> {after:.3} mm");
            for (layer, was) in faired.iter().zip(&noisy) {
                let ring = Contour { points: layer.points.clone() };
                let kept =
                    preserve.girth(&ring) - preserve.girth(&Contour { points: was.points.clone() });
                assert!(kept.abs() < 1e-9, "{preserve:?} at {}: {kept:+e} mm", layer.z);
                let n = layer.points.len();
                for (j, p) in layer.points.iter().enumerate() {
                    let partner = layer.points[n - 1 - j];
                    assert!((p.x + partner.x).abs() < 1e-9 && (p.y - partner.y).abs() < 1e-9);
                }
            }
        }
    }

    #[test]
    fn a_fold_of_the_body_moves_at_most_the_limit() {
        // A groove 8 mm deep and 20 mm tall across the front (as under the bust) on a
        // 150 mm cylinder (all round, it would be a girth, given back whole).
        let groove = |z: f64, i: usize| {
            let front = if i < 40 { 1.0 } else { 0.0 };
            150.0 - front * 8.0 * (-((z - 1100.0) / 10.0).powi(2)).exp()
        };
        let body = rings(30, 0.0, groove);
        let mut faired = body.clone();
        fair(&mut faired, &|_, _| false, Preserve::Tape, true);
        let moved = faired
            .iter()
            .zip(&body)
            .flat_map(|(a, b)| a.points.iter().zip(&b.points).map(|(p, q)| p.distance(*q)))
            .fold(0.0, f64::max);
        // The limit, and the girth given back (a fraction of a millimetre here).
        assert!(moved > 0.5 && moved < MAX_MOVE_MM + 0.5, "moved {moved:.2} mm");
    }

    #[test]
    fn points_on_an_arm_plate_stay_on_it() {
        // A plate at x = 140 mm from z = 1050 up, leaning out 10 degrees as it rises.
        let lean = 10f64.to_radians();
        let plate = Armhole {
            armpit: DVec3::new(140.0, 0.0, 1050.0),
            shoulder_point: DVec3::new(140.0 + 100.0 * lean.tan(), 0.0, 1150.0),
            normal: DVec3::new(lean.cos(), 0.0, -lean.sin()),
            contact: None,
        };
        let mirrored = Armhole {
            armpit: plate.armpit * DVec3::new(-1.0, 1.0, 1.0),
            shoulder_point: plate.shoulder_point * DVec3::new(-1.0, 1.0, 1.0),
            normal: plate.normal * DVec3::new(-1.0, 1.0, 1.0),
            ..plate
        };
        // Rings cut flat at the plates, with noise elsewhere.
        let mut cut = rings(30, 0.0, |z, i| 150.0 + 0.3 * noise(i * 31 + z as usize));
        for layer in &mut cut {
            for p in &mut layer.points {
                for a in [&plate, &mirrored] {
                    let beyond = a.normal.dot(p.extend(layer.z) - a.armpit);
                    if layer.z >= a.armpit.z && beyond > 0.0 {
                        let along = DVec2::new(a.normal.x, a.normal.y).length_squared();
                        *p -= DVec2::new(a.normal.x, a.normal.y) * (beyond / along);
                    }
                }
            }
        }
        let mut faired = cut.clone();
        let heights: Vec<f64> = cut.iter().map(|l| l.z).collect();
        let plates = [&plate, &mirrored];
        fair(&mut faired, &|k, p| on_plates(&plates, p, heights[k]), Preserve::Tape, true);
        for (layer, was) in faired.iter().zip(&cut) {
            for (p, q) in layer.points.iter().zip(&was.points) {
                let on = [&plate, &mirrored].iter().any(|a| on(a, *q, layer.z));
                if on {
                    // Moved only by the girth's rescale (0.1 mm here); averaged with the
                    // uncut layers below, the lowest plate's chord would move out 1 mm.
                    assert!(p.distance(*q) < 0.25, "a plate point moved {:.3} mm", p.distance(*q));
                }
            }
        }
    }
}
