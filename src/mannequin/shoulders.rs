//! The shoulders' top, eased into a dress form's slope.
//!
//! Above the shoulder points the torso layers narrow from the arm plates to the neck. Where a
//! body's shoulder top is nearly level (square shoulders, the flat top of a shoulder cap, a
//! coarse mesh's flat polygon), two horizontal layers a few millimetres apart differ in width
//! by a lot and the surface between them is a ledge. A dress form's shoulder slopes, so above
//! the widest layer (at the shoulder points, which stays as it is) neighbouring layers may
//! differ in width by at most [`MAX_WIDTH_PER_MM`] per millimetre of height.
//!
//! Where they differ by more, the layers' widths are eased by about the least largest change
//! that meets the limit: the layers below the ledge narrow and those above widen by about as
//! much (the mean of the narrowest and the widest width sequences within the limit), while
//! the widest layer and the neck keep their widths, so the neck is not widened into a box:
//! from a short neck the shoulders slope down at the limit (a neck too short even for that is
//! widened as little as the limit allows). An eased
//! layer takes the shape the layers have a little higher up (to narrow) or lower down (to
//! widen) where that shape is just as wide: the layers are read as one surface, each ray
//! running straight from one layer to the next, as the rebuilt mesh joins them. So the
//! shoulder top keeps its own shape and slopes as a dress form's does. An eased layer has the
//! girth of its new shape; every other layer keeps its section's. A shoulder sloping more than
//! about 16 degrees is left as it is.

use super::Layer;
use crate::slice::Contour;
use glam::DVec2;

/// Largest change of width between neighbouring layers above the shoulder points, per
/// millimetre of height: 7 mm, so that the width changes by at most 14 mm between slices 2 mm
/// apart (a smooth body stays under 15 mm there, issue 12); a shoulder sloping 16 degrees or
/// more meets it.
const MAX_WIDTH_PER_MM: f64 = 7.0;

/// Bisection steps within a gap between two layers (to 2^-40 of the gap).
const BISECTION_STEPS: usize = 40;

/// Width of a ring about the symmetry plane x = `axis`: twice its largest distance from it.
fn width(points: &[DVec2], axis: f64) -> f64 {
    2.0 * points.iter().map(|p| (p.x - axis).abs()).fold(0.0, f64::max)
}

/// The widths changing by at most `limit` per mm closest to `w` (at heights `z`, ascending),
/// the first (the widest layer) and, where it can be, the last (the neck) kept: the mean of the smallest
/// sequence within the limit above `w` and the largest below it (the closest such sequence
/// in the largest difference), clamped to the band the kept ends leave (so the neck is not
/// widened into a box and the shoulders slope down from it).
fn eased_widths(z: &[f64], w: &[f64], limit: f64) -> Vec<f64> {
    let n = w.len();
    let reach = |k: usize| limit * (z[k] - z[k - 1]);
    let (mut upper, mut lower) = (w.to_vec(), w.to_vec());
    for k in 1..n {
        upper[k] = upper[k].max(upper[k - 1] - reach(k));
        lower[k] = lower[k].min(lower[k - 1] + reach(k));
    }
    for k in (0..n - 1).rev() {
        upper[k] = upper[k].max(upper[k + 1] - reach(k + 1));
        lower[k] = lower[k].min(lower[k + 1] + reach(k + 1));
    }
    let (first, last) = (w[0], w[n - 1]);
    let (z0, zn) = (z[0], z[n - 1]);
    // A neck too short for the shoulders to slope down to it within the limit is widened
    // (as little as the limit allows) rather than the layer at the shoulder points narrowed.
    let neck_kept = (first - last).abs() <= limit * (zn - z0);
    (0..n)
        .map(|k| {
            let (below, above) = (limit * (z[k] - z0), limit * (zn - z[k]));
            let (mut lo, mut hi) = (first - below, first + below);
            if neck_kept {
                (lo, hi) = (lo.max(last - above), hi.min(last + above));
            }
            (0.5 * (upper[k] + lower[k])).clamp(lo, hi)
        })
        .collect()
}

/// The layers read as one surface: the ring at height `z` between layers `k` and `k + 1`,
/// each ray's point straight between theirs. Returns (centre, points).
fn surface_at(layers: &[Layer], k: usize, z: f64) -> (DVec2, Vec<DVec2>) {
    let (a, b) = (&layers[k], &layers[k + 1]);
    let t = ((z - a.z) / (b.z - a.z)).clamp(0.0, 1.0);
    let centre = DVec2::from_array(a.centre).lerp(DVec2::from_array(b.centre), t);
    (centre, a.points.iter().zip(&b.points).map(|(p, q)| p.lerp(*q, t)).collect())
}

/// The shape of the surface of `layers` nearest to layer `k` that is `target` wide: looked
/// for upwards to narrow, downwards to widen. Returns (centre, points), or `None` where no
/// part of the surface is that wide.
fn shape_of_width(
    layers: &[Layer],
    k: usize,
    target: f64,
    axis: f64,
) -> Option<(DVec2, Vec<DVec2>)> {
    let w = |gap: usize, z: f64| width(&surface_at(layers, gap, z).1, axis);
    let gaps: Vec<usize> = if target < width(&layers[k].points, axis) {
        (k..layers.len() - 1).collect()
    } else {
        (0..k).rev().collect()
    };
    gaps.into_iter().find_map(|gap| {
        let (lo, hi) = (layers[gap].z, layers[gap + 1].z);
        let w_lo = w(gap, lo);
        if (w_lo - target) * (w(gap, hi) - target) > 0.0 {
            return None;
        }
        let (mut a, mut b) = (lo, hi);
        for _ in 0..BISECTION_STEPS {
            let mid = 0.5 * (a + b);
            if (w(gap, mid) - target) * (w_lo - target) > 0.0 { a = mid } else { b = mid }
        }
        Some(surface_at(layers, gap, 0.5 * (a + b)))
    })
}

/// The fastest change of width (per mm of height) of the surface through `layers`, between
/// slices `SLICE_STEPS` to a gap apart: where the widest ray changes between two layers, a
/// slice between them can change faster than the layers do.
fn fastest_change(layers: &[Layer], axis: f64) -> f64 {
    let mut fastest: f64 = 0.0;
    for gap in 0..layers.len().saturating_sub(1) {
        let (lo, hi) = (layers[gap].z, layers[gap + 1].z);
        let w = |s: usize| {
            let z = lo + (hi - lo) * s as f64 / SLICE_STEPS as f64;
            width(&surface_at(layers, gap, z).1, axis)
        };
        for s in 0..SLICE_STEPS {
            fastest = fastest.max((w(s + 1) - w(s)).abs() / ((hi - lo) / SLICE_STEPS as f64));
        }
    }
    fastest
}

/// Slices per gap between layers at which [`fastest_change`] looks.
const SLICE_STEPS: usize = 8;
/// Rounds of [`ease`], each with the layers' limit tightened by how far the surface between
/// them still overshot.
const ROUNDS: usize = 4;

/// The layers of `zone` (the widest first) with their widths eased to change by at most
/// `limit` per mm between layers.
fn eased(zone: &[Layer], axis: f64, limit: f64) -> Vec<Layer> {
    let z: Vec<f64> = zone.iter().map(|l| l.z).collect();
    let widths: Vec<f64> = zone.iter().map(|l| width(&l.points, axis)).collect();
    let mut out = zone.to_vec();
    for (k, (&target, &own)) in eased_widths(&z, &widths, limit).iter().zip(&widths).enumerate() {
        if (target - own).abs() <= f64::EPSILON * own {
            continue;
        }
        let Some((centre, points)) = shape_of_width(zone, k, target, axis) else { continue };
        let ring = Contour { points };
        let layer = &mut out[k];
        layer.centre = centre.to_array();
        layer.tape_girth = ring.tape_girth();
        layer.contour_length = ring.perimeter();
        layer.points = ring.points;
    }
    out
}

/// Eases the torso layers above the widest one from the last layer at or below `from_z` (the
/// lower shoulder point) up, about the symmetry plane x = `axis` (see the module
/// documentation). The layer just below the shoulder point is a candidate because the ledge
/// can begin right above it.
pub(super) fn ease(torso: &mut [Layer], axis: f64, from_z: f64) {
    let first = torso.iter().rposition(|l| l.z <= from_z).unwrap_or(0);
    let Some(widest) = (first..torso.len())
        .max_by(|&a, &b| width(&torso[a].points, axis).total_cmp(&width(&torso[b].points, axis)))
    else {
        return;
    };
    let zone = &mut torso[widest..];
    let mut limit = MAX_WIDTH_PER_MM;
    let mut out = eased(zone, axis, limit);
    for _ in 1..ROUNDS {
        let fastest = fastest_change(&out, axis);
        if fastest <= MAX_WIDTH_PER_MM {
            break;
        }
        limit *= MAX_WIDTH_PER_MM / fastest;
        out = eased(zone, axis, limit);
    }
    zone.clone_from_slice(&out);
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::regions::Region;
    use std::f64::consts::TAU;

    /// A layer at height `z`: an ellipse `a` wide (half-width) and `b` deep about x = 0.
    fn ellipse(z: f64, a: f64, b: f64) -> Layer {
        let points: Vec<DVec2> = (1..36)
            .filter(|&i| i != 18)
            .map(|i| {
                let t = 1.5 * std::f64::consts::PI + TAU * i as f64 / 36.0;
                DVec2::new(a * t.cos(), b * t.sin())
            })
            .collect();
        let ring = Contour { points: points.clone() };
        Layer {
            region: Region::Torso,
            z,
            centre: [0.0, 0.0],
            points,
            input_tape_girth: ring.tape_girth(),
            input_contour_length: ring.perimeter(),
            tape_girth: ring.tape_girth(),
            contour_length: ring.perimeter(),
        }
    }

    #[test]
    fn a_level_shoulder_is_eased_and_a_sloping_one_is_kept() {
        // Layers 10 mm apart: below the shoulder points, the shoulder points, a sloping
        // shoulder (60 mm narrower, 70 allowed), a ledge of 200 mm, the neck.
        let mut torso = vec![
            ellipse(-10.0, 180.0, 80.0),
            ellipse(0.0, 200.0, 80.0),
            ellipse(10.0, 190.0, 80.0),
            ellipse(20.0, 160.0, 75.0),
            ellipse(30.0, 60.0, 60.0),
            ellipse(40.0, 55.0, 55.0),
            ellipse(50.0, 52.0, 52.0),
        ];
        let kept: Vec<Vec<DVec2>> = torso.iter().map(|l| l.points.clone()).collect();
        ease(&mut torso, 0.0, -10.0);
        for k in [0, 1] {
            assert_eq!(torso[k].points, kept[k], "layer {k}: below the widest and the widest");
        }
        let widths: Vec<f64> = torso.iter().map(|l| width(&l.points, 0.0)).collect();
        for k in 2..widths.len() {
            assert!((widths[k - 1] - widths[k]).abs() <= 70.0 + 1e-6, "{widths:?}");
        }
        assert!(widths[3] < 320.0 && widths[4] > 120.0, "narrower below, wider above: {widths:?}");
        for l in &torso {
            let ring = Contour { points: l.points.clone() };
            assert!((ring.tape_girth() - l.tape_girth).abs() < 1e-9, "girths say what they are");
        }
    }

    #[test]
    fn eased_widths_meet_the_limit_with_both_ends_kept() {
        let z = [0.0, 10.0, 20.0, 30.0];
        assert_eq!(
            eased_widths(&z, &[400.0, 350.0, 300.0, 260.0], 7.0),
            vec![400.0, 350.0, 300.0, 260.0]
        );
        let eased = eased_widths(&z, &[400.0, 395.0, 195.0, 190.0], 7.0);
        assert_eq!((eased[0], eased[3]), (400.0, 190.0));
        for k in 1..4 {
            assert!((eased[k - 1] - eased[k]).abs() <= 70.0 + 1e-9, "{eased:?}");
        }
        // A neck too short to slope down to: the widest layer stays, the neck widens.
        let eased = eased_widths(&z, &[400.0, 390.0, 120.0, 100.0], 7.0);
        assert_eq!(eased[0], 400.0);
        assert!(eased[3] > 100.0, "{eased:?}");
        for k in 1..4 {
            assert!((eased[k - 1] - eased[k]).abs() <= 70.0 + 1e-9, "{eased:?}");
        }
    }
}
