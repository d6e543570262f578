//! The arm plates' rims: one smooth curve on each plate.
//!
//! Each torso section between the armpits and the shoulder points is cut at both armholes and
//! made symmetric by rays from its centre (paper eq. 5-8): the cut becomes a straight chord,
//! but its two ends (the rim's corners) fall between two rays, so the ring cuts each corner
//! off, at a different place on every layer, and the bands between the rings joined the chord
//! of one ring to the torso side of the next: seen from the side, the plate's rim was a
//! staircase, one step per layer (6.6 mm at the paper's 100 torso layers).
//!
//! So each mesh ring in that zone is cut again at the mannequin's own (mirror-symmetric) arm
//! plates, the points between a side's two corners are laid on the plate (the averaged chord
//! of an asymmetric body strays from it by the asymmetry), and each corner is put back where
//! the ring's side, continued straight, meets the plate; the ring is then stretched front to
//! back until it has its layer's girth again (the plates run front to back, so the chords stay
//! on them). Where two neighbouring rings both meet the plates, the band between them is
//! stitched with their corners' parameters aligned, so corner meets corner
//! ([`super::rebuild`]): the rim is one curve through the rings' corners, and the plate inside
//! it is flat. The torso layers themselves (`profiles.json`) keep their rays.

use super::Layer;
use super::rebuild::TorsoRing;
use crate::regions::Armhole;
use crate::slice::Contour;
use crate::symmetry::Preserve;
use glam::{DVec2, DVec3};

/// A point is on a plate within this distance (mm): far below a scan's noise, far above the
/// rounding of a cut.
const ON_PLATE_MM: f64 = 1e-6;

/// How far a ring's side is continued to find its corner on a plate, in lengths of its last
/// edge: the corner lies between the last ray on the side and the first on the plate.
const CORNER_REACH: f64 = 1.0;

/// Most rounds of the secant search for the stretch that gives a ring back its girth: each
/// round squares the relative error, so five reach rounding from a few millimetres.
const GIRTH_ROUNDS: usize = 8;

/// A ring has its girth back within this (mm): far below the 0.1 mm a layer may change.
const GIRTH_TOLERANCE_MM: f64 = 1e-9;

/// How far `p` lies on the torso's side of the plate `plate` in the horizontal plane at `z`
/// (mm, negative beyond it): linear in `p`.
fn inside(plate: &Armhole, z: f64, p: DVec2) -> f64 {
    -plate.beyond(p.extend(z))
}

/// The first and last points of `points` on `side` (+1 left, -1 right) of the plane x =
/// `axis` that lie on the plate (`inside` zero): the ends of the ring's chord on that plate.
fn chord_ends(
    points: &[DVec2],
    axis: f64,
    side: f64,
    inside: &impl Fn(DVec2) -> f64,
) -> Option<(usize, usize)> {
    let on =
        |k: &usize| side * (points[*k].x - axis) > 0.0 && inside(points[*k]).abs() <= ON_PLATE_MM;
    let first = (0..points.len()).find(on)?;
    let last = (0..points.len()).rev().find(on)?;
    (first < last).then_some((first, last))
}

/// Where the ring's side, the edge from `before` to `at` continued straight, meets the plate
/// (`inside` zero), if within [`CORNER_REACH`] of `at`.
fn corner(before: DVec2, at: DVec2, inside: &impl Fn(DVec2) -> f64) -> Option<DVec2> {
    let (f0, f1) = (inside(at), inside(at + (at - before)));
    let s = f0 / (f0 - f1);
    (f0 > 0.0 && s > 0.0 && s <= CORNER_REACH).then(|| at + (at - before) * s)
}

/// `points` cut at the plate on `side` (`inside` its torso side), the chord laid on it and its
/// corners put back (see the module documentation).
fn cut_side(points: &mut Vec<DVec2>, axis: f64, side: f64, inside: &impl Fn(DVec2) -> f64) {
    *points = Contour { points: std::mem::take(points) }.keep_where(inside).points;
    let Some((first, last)) = chord_ends(points, axis, side, inside) else { return };
    // `inside` is linear: its gradient is the plate's inward normal in the plane.
    let normal =
        DVec2::new(inside(DVec2::X) - inside(DVec2::ZERO), inside(DVec2::Y) - inside(DVec2::ZERO));
    for p in &mut points[first + 1..last] {
        *p -= normal * (inside(*p) / normal.length_squared().max(f64::MIN_POSITIVE));
    }
    let n = points.len();
    let same_side = |k: usize| side * (points[k].x - axis) > 0.0;
    // A corner lies beyond its end of the chord, never back over the chord (where a side
    // curls, its straight continuation may meet the plate there).
    let along = points[last] - points[first];
    let (after, after2) = ((last + 1) % n, (last + 2) % n);
    let back = if same_side(after) && same_side(after2) {
        corner(points[after2], points[after], inside)
    } else {
        None
    };
    let front = if first >= 2 && same_side(first - 1) && same_side(first - 2) {
        corner(points[first - 2], points[first - 1], inside)
    } else {
        None
    };
    let (back, front) = (
        back.filter(|c| (*c - points[last]).dot(along) > 0.0),
        front.filter(|c| (points[first] - *c).dot(along) > 0.0),
    );
    if let Some(c) = back {
        points.insert(last + 1, c);
    }
    if let Some(c) = front {
        points.insert(first, c);
    }
}

/// `points` stretched front to back about the line y = `centre_y` until the girth `preserve`
/// measures is `girth` (a secant search). The plates' lines run front to back (their normals
/// have no y part, [`Armhole::through`]), so the chords stay on them, and the ring stays
/// mirror-symmetric.
fn with_girth(points: &[DVec2], centre_y: f64, girth: f64, preserve: Preserve) -> Vec<DVec2> {
    let stretched = |s: f64| -> Vec<DVec2> {
        points.iter().map(|p| DVec2::new(p.x, centre_y + (p.y - centre_y) * s)).collect()
    };
    let error = |s: f64| preserve.girth(&Contour { points: stretched(s) }) - girth;
    let (mut a, mut fa) = (1.0, error(1.0));
    let mut b = 1.0 - fa / girth;
    for _ in 0..GIRTH_ROUNDS {
        let fb = error(b);
        if fb.abs() <= GIRTH_TOLERANCE_MM || fb == fa {
            break;
        }
        (a, fa, b) = (b, fb, b - fb * (b - a) / (fb - fa));
    }
    stretched(b)
}

/// The mesh ring of the horizontal torso `layer`, about the plane x = `axis`: where the layer
/// lies between the plates' armpits and shoulder points, cut at the mannequin's own plates
/// `[left, right]` with its corners put back and stretched to keep the girth `preserve` measures
/// (see the module documentation); elsewhere the layer's ring as it is.
pub(super) fn rim(
    layer: &Layer,
    axis: f64,
    plates: [&Armhole; 2],
    preserve: Preserve,
) -> TorsoRing {
    let centre = DVec2::from_array(layer.centre);
    let z = layer.z;
    let on_plates = plates.iter().all(|p| p.armpit.z <= z && z < p.shoulder_point.z);
    let level: Vec<DVec3> = layer.points.iter().map(|p| p.extend(z)).collect();
    if !on_plates {
        return TorsoRing::from_rays(&level);
    }
    let insides = plates.map(|plate| move |p: DVec2| inside(plate, z, p));
    let mut points = layer.points.clone();
    for (inside, side) in insides.iter().zip([1.0, -1.0]) {
        cut_side(&mut points, axis, side, inside);
    }
    let chords: Vec<(usize, usize)> = insides
        .iter()
        .zip([1.0, -1.0])
        .filter_map(|(f, side)| chord_ends(&points, axis, side, f))
        .collect();
    if chords.is_empty() {
        return TorsoRing::from_rays(&level);
    }
    let girth = preserve.girth(&Contour { points: layer.points.clone() });
    let points = with_girth(&points, centre.y, girth, preserve);
    TorsoRing::with_corners(points, z, centre, axis, &chords)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::regions::Region;
    use crate::symmetry::axial;
    use std::f64::consts::TAU;

    #[test]
    fn the_corners_come_back_on_the_plates_with_the_girth_kept() {
        // An ellipse 260 x 180 mm cut by two upright plates at x = +-100 mm, made symmetric by
        // rays: the corners where the plates meet the ellipse lie at y = +-90 sqrt(1 - (100/130)^2).
        let ellipse = Contour {
            points: (0..2000)
                .map(|k| {
                    let t = TAU * k as f64 / 2000.0;
                    DVec2::new(130.0 * t.cos(), 90.0 * t.sin())
                })
                .collect(),
        };
        let section = ellipse.clip_x(-100.0, 100.0);
        let ring = axial::symmetrize(&section, 0.0, 360, Preserve::Tape).unwrap();
        let girth = Contour { points: ring.points.clone() }.tape_girth();
        let layer = Layer {
            region: Region::Torso,
            z: 50.0,
            centre: ring.centre.to_array(),
            points: ring.points,
            input_tape_girth: girth,
            input_contour_length: girth,
            tape_girth: girth,
            contour_length: girth,
        };
        let plate = |x: f64, side: f64| {
            Armhole::through(DVec3::new(x, 0.0, 0.0), DVec3::new(x, 0.0, 100.0), DVec3::NEG_Y, side)
        };
        let (left, right) = (plate(100.0, 1.0), plate(-100.0, -1.0));
        let rimmed = rim(&layer, 0.0, [&left, &right], Preserve::Tape);

        let corners = rimmed.corners.expect("the ring meets both plates");
        let corner_y = 90.0 * (1.0 - (100.0_f64 / 130.0).powi(2)).sqrt();
        for (k, (x, y)) in corners.into_iter().zip([(1., -1.), (1., 1.), (-1., 1.), (-1., -1.)]) {
            let p = rimmed.points[k];
            assert!((p.x - 100.0 * x).abs() < 1e-9, "corner {p} off its plate");
            assert!((p.y - corner_y * y).abs() < 0.1, "corner {p}, not at y = {}", corner_y * y);
        }
        let flat: Vec<DVec2> = rimmed.points.iter().map(|p| p.truncate()).collect();
        assert!((Contour { points: flat.clone() }.tape_girth() - girth).abs() < 1e-6);
        for p in &flat {
            assert!(flat.iter().any(|q| (q.x + p.x).abs() < 1e-9 && (q.y - p.y).abs() < 1e-9));
        }
    }
}
