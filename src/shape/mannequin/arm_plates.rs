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
//! the ring's side, continued straight, meets the plate; the ring's sides are then stretched
//! front to back until it has its layer's girth again (the plates run front to back, so the
//! chords stay on them; the front and back stay where the faired layer has them: stretched
//! whole, they stood 1.1 mm out across the demo's back near the plate bottom, a band). Where
//! two neighbouring rings both meet the plates, the band between them is stitched with their
//! corners' parameters aligned, so corner meets corner
//! ([`super::rebuild`]): the rim is one curve through the rings' corners, and the plate inside
//! it is flat. The torso layers themselves (`profiles.json`) keep their rays.
//!
//! The first ring to meet a plate does so with a chord as long as the body's side is flat
//! there (9-48 mm on the generator's bodies, 31 on the demo customer's, whose scan has a hole
//! in the armpit that the slicer bridges straight), over a ring that does not reach it: seen
//! from the side, the rim had a flat bottom. A dress form's plate is round at the bottom, so
//! the rim's lower edge is drawn in the plate's own plane ([`Bottom`]): each ring's chord is
//! kept only where the rim is at most [`Bottom::half_width`] from its middle, and the ring's
//! side beyond is drawn back off the plate ([`narrow`]).

use super::fairing::PLATE_BAND_MM;
use super::rebuild::TorsoRing;
use super::{Layer, smoothstep};
use crate::body::regions::Armhole;
use crate::body::slice::Contour;
use crate::shape::symmetry::Preserve;
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

/// Half the chord (mm) the lowest ring keeps on a plate: about one ray's spacing at a torso's
/// side (1 degree at 160-200 mm from the centre, 2.8-3.5 mm), so the rim's bottom is one or
/// two edges, not a flat chord.
const BOTTOM_HALF_MM: f64 = 3.0;

/// The radius of the rim's lower edge (mm): a dress form's arm plate is about 100 mm wide and
/// round at the bottom. With it the rim is 53 mm wide one layer (6.8 mm) above its bottom and
/// 74 two layers above; the demo customer's own rim is 55 and 72 wide there, so only the
/// lowest rings are drawn in.
const BOTTOM_RADIUS_MM: f64 = 50.0;

/// The radius (mm) with which a ring's side is drawn back off the plate beyond its kept chord:
/// a side drawn back is `s^2 / (2 r)` deep at `s` beyond the chord's end, 5.6 mm at the demo's
/// 15 mm, but at most [`BELOW_SHARE`] of the way to the ring below.
const DRAW_RADIUS_MM: f64 = 20.0;

/// How far towards the ring below (in depth under the plate) a side is drawn back at most:
/// half way, so the surface from the ring below up to the plate leans evenly and no groove
/// runs under the rim; the girth a ring loses (and gets back by stretching front to back,
/// which shows as a faint line across the torso) stays small.
const BELOW_SHARE: f64 = 0.5;

/// Over this length of the ring (mm) beyond the end of its natural chord, a side drawn back
/// eases into the ring as it was: about two rays' spacing at a torso's side.
const EASE_MM: f64 = 8.0;

/// The rim's lower edge: the lowest ring on the plates, at height `z`, keeps its chord only
/// within [`BOTTOM_HALF_MM`] of `middle` (the chord's middle, front to back); the rings above
/// keep theirs within [`Bottom::half_width`], a parabola of radius [`BOTTOM_RADIUS_MM`] at
/// its vertex.
#[derive(Debug, Clone, Copy)]
struct Bottom {
    z: f64,
    middle: f64,
    half: f64,
}

impl Bottom {
    /// The lower edge of the plates met first by `ring` (at height `z`), if it meets them.
    fn of(ring: &TorsoRing, z: f64) -> Option<Bottom> {
        let [front, back, ..] = ring.corners?;
        let (a, b) = (ring.points[front].y, ring.points[back].y);
        Some(Bottom { z, middle: 0.5 * (a + b), half: BOTTOM_HALF_MM.min(0.5 * (b - a).abs()) })
    }

    /// How far (mm) a ring's chord at height `z` may reach beyond [`Bottom::half_width`] and
    /// still be kept whole: none on the lowest ring; a ray's spacing ([`BOTTOM_HALF_MM`]) above
    /// it, where a chord whose corner lay 0.2 mm beyond had that corner doubled (MakeHuman's rim
    /// turned 85 and 58 degrees there, 530 in all).
    fn slack(&self, z: f64) -> f64 {
        if z > self.z { BOTTOM_HALF_MM } else { 0.0 }
    }

    /// Half the width (mm) of the rim at height `z`: `sqrt(half^2 + 2 R (z - z0))`.
    fn half_width(&self, z: f64) -> f64 {
        (self.half.powi(2) + 2.0 * BOTTOM_RADIUS_MM * (z - self.z).max(0.0)).sqrt()
    }
}

/// How deep the ring `below` lies inside the plate (`inside`) on `side` at the front-to-back
/// position `y`: its outermost crossing of that line (`None` where it has none).
fn depth_below(
    below: &[DVec2],
    axis: f64,
    side: f64,
    inside: &impl Fn(DVec2) -> f64,
    y: f64,
) -> Option<f64> {
    let n = below.len();
    (0..n)
        .filter_map(|k| {
            let (a, b) = (below[k], below[(k + 1) % n]);
            let on_side = side * (a.x - axis) > 0.0 && side * (b.x - axis) > 0.0;
            let spans = (a.y - y) * (b.y - y) <= 0.0 && a.y != b.y;
            (on_side && spans).then(|| inside(a.lerp(b, (y - a.y) / (b.y - a.y))))
        })
        .min_by(f64::total_cmp)
}

/// `points`, cut at the plate on `side` (`inside` its torso side), with their chord kept only
/// within `half` of `middle` (front to back), where it reaches more than `slack` beyond: the chord's points beyond are drawn back off the
/// plate, `s^2 / (2` [`DRAW_RADIUS_MM`]`)` deep at `s` beyond the kept chord's end, and the
/// side beyond the chord's own end eased back over [`EASE_MM`] of its length; no point is
/// drawn more than [`BELOW_SHARE`] of the way to the ring `below` at its front-to-back
/// position. Points move along
/// the plate's normal, which has no y part ([`Armhole::through`]).
fn narrow(
    points: &mut Vec<DVec2>,
    axis: f64,
    side: f64,
    inside: &impl Fn(DVec2) -> f64,
    (middle, half, slack): (f64, f64, f64),
    below: &[DVec2],
) {
    let Some((first, last)) = chord_ends(points, axis, side, inside) else { return };
    let off = |p: DVec2| (p.y - middle).abs() - half;
    if (first..=last).all(|k| off(points[k]) <= slack) {
        return;
    }
    let draw = |s: f64| s.max(0.0).powi(2) / (2.0 * DRAW_RADIUS_MM);
    let normal =
        DVec2::new(inside(DVec2::X) - inside(DVec2::ZERO), inside(DVec2::Y) - inside(DVec2::ZERO));
    let n = points.len();
    // How far each point is drawn back, before the cap by the ring below.
    let mut drawn = vec![0.0; n];
    for k in first..=last {
        drawn[k] = draw(off(points[k]));
    }
    let same_side = |p: DVec2| side * (p.x - axis) > 0.0;
    for (end, step) in [(first, n - 1), (last, 1)] {
        let (depth, mut along, mut k) = (drawn[end], 0.0, end);
        loop {
            let next = (k + step) % n;
            along += points[k].distance(points[next]);
            if along >= EASE_MM || !same_side(points[next]) || (first..=last).contains(&next) {
                break;
            }
            drawn[next] = drawn[next].max(depth * (1.0 - smoothstep(along / EASE_MM)));
            k = next;
        }
    }
    let moved: Vec<DVec2> = points
        .iter()
        .zip(&drawn)
        .map(|(&p, &d)| {
            if d <= 0.0 {
                return p;
            }
            let own = inside(p);
            let floor = depth_below(below, axis, side, inside, p.y).unwrap_or(own).max(own);
            let target = (own + d).min(own + BELOW_SHARE * (floor - own));
            p + normal * ((target - own) / normal.length_squared().max(f64::MIN_POSITIVE))
        })
        .collect();
    // The kept chord's ends, on the plate where the chord's edges cross them.
    let mut out = Vec::with_capacity(n + 2);
    for k in 0..n {
        out.push(moved[k]);
        if (first..last).contains(&k) {
            let (p, q) = (points[k], points[k + 1]);
            let mut at: Vec<f64> = [middle - half, middle + half]
                .iter()
                .map(|y| (y - p.y) / (q.y - p.y))
                .filter(|t| *t > 0.0 && *t < 1.0)
                .collect();
            at.sort_by(f64::total_cmp);
            out.extend(at.iter().map(|&t| p.lerp(q, t)));
        }
    }
    *points = out;
}

/// From this fraction of a ring's half-width out, the girth its drawn-back sides lost is given
/// back ([`lateral`]): the front and back (the bust, the shoulder blades) stay where the rings
/// below and above have them; stretched whole, the ring stood out across the torso's front
/// and back as a line 1.5 mm proud on MakeHuman.
const LATERAL_FROM: f64 = 0.5;

/// How much of a front-to-back stretch the point `p` of a ring `half` wide about x = `axis`
/// takes: none within [`LATERAL_FROM`] of its half-width, all at its sides, smoothly between.
fn lateral(p: DVec2, axis: f64, half: f64) -> f64 {
    smoothstep(((p.x - axis).abs() / half - LATERAL_FROM) / (1.0 - LATERAL_FROM))
}

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
/// corners put back (see the module documentation). A side that stops short of the plate by
/// less than [`PLATE_BAND_MM`] (on it, as the fairing takes it) has its points within that
/// band laid on it: eq. 8 scales a layer about its centre to its section's girth, which can
/// draw a chord back off the plate (0.4 mm on the demo's re-posed customer, whose lowest ring
/// on the plates then kept its whole 26 mm chord under the rim's round bottom: a flat tab).
fn cut_side(points: &mut Vec<DVec2>, axis: f64, side: f64, inside: &impl Fn(DVec2) -> f64) {
    // `inside` is linear: its gradient is the plate's inward normal in the plane.
    let normal =
        DVec2::new(inside(DVec2::X) - inside(DVec2::ZERO), inside(DVec2::Y) - inside(DVec2::ZERO));
    let onto = |p: DVec2| p - normal * (inside(p) / normal.length_squared().max(f64::MIN_POSITIVE));
    *points = Contour { points: std::mem::take(points) }.keep_where(inside).points;
    if chord_ends(points, axis, side, inside).is_none() {
        let near = |p: &DVec2| side * (p.x - axis) > 0.0 && inside(*p) <= PLATE_BAND_MM;
        for p in points.iter_mut().filter(|p| near(p)) {
            *p = onto(*p);
        }
    }
    let Some((first, last)) = chord_ends(points, axis, side, inside) else { return };
    for p in &mut points[first + 1..last] {
        *p = onto(*p);
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
fn with_girth(
    points: &[DVec2],
    centre_y: f64,
    girth: f64,
    preserve: Preserve,
    weight: impl Fn(DVec2) -> f64,
) -> Vec<DVec2> {
    let weights: Vec<f64> = points.iter().map(|&p| weight(p)).collect();
    let stretched = |s: f64| -> Vec<DVec2> {
        let at = |p: &DVec2, w: f64| centre_y + (p.y - centre_y) * (1.0 + (s - 1.0) * w);
        points.iter().zip(&weights).map(|(p, &w)| DVec2::new(p.x, at(p, w))).collect()
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

/// The mesh rings of the horizontal torso `layers` (bottom to top, all below the shoulder
/// cap), about the plane x = `axis`, each as [`rim`] makes it; from the first ring to meet the
/// plates up, their chords are kept within the rim's lower edge ([`Bottom`]), each ring drawn
/// back at most half way to the (drawn) ring below it.
pub(super) fn rims(
    layers: &[Layer],
    axis: f64,
    plates: [&Armhole; 2],
    preserve: Preserve,
) -> Vec<TorsoRing> {
    let mut rings: Vec<TorsoRing> =
        layers.iter().map(|layer| rim(layer, axis, plates, preserve, None)).collect();
    let Some(k) = (1..rings.len()).find(|&k| rings[k].corners.is_some()) else { return rings };
    let Some(bottom) = Bottom::of(&rings[k], layers[k].z) else { return rings };
    for j in k..rings.len() {
        let below: Vec<DVec2> = rings[j - 1].points.iter().map(|p| p.truncate()).collect();
        rings[j] = rim(&layers[j], axis, plates, preserve, Some((bottom, &below)));
    }
    rings
}

/// The mesh ring of the horizontal torso `layer`, about the plane x = `axis`: where the layer
/// lies between the plates' armpits and shoulder points, cut at the mannequin's own plates
/// `[left, right]` with its corners put back, its chords kept within the rim's lower edge
/// `bottom` (at most half way to the ring `below`, [`narrow`]) where given, and stretched to keep
/// the girth `preserve` measures (see the module documentation); elsewhere the layer's ring as
/// it is.
fn rim(
    layer: &Layer,
    axis: f64,
    plates: [&Armhole; 2],
    preserve: Preserve,
    bottom: Option<(Bottom, &[DVec2])>,
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
    let girth = preserve.girth(&Contour { points: layer.points.clone() });
    let half = |points: &[DVec2]| points.iter().map(|p| (p.x - axis).abs()).fold(0.0, f64::max);
    // The girth the cut changed, given back beside the plates (see [`lateral`]).
    if chord_ends(&points, axis, 1.0, &insides[0]).is_some() {
        let half = half(&points);
        points = with_girth(&points, centre.y, girth, preserve, |p| lateral(p, axis, half));
    }
    if let Some((bottom, below)) = bottom {
        let kept = (bottom.middle, bottom.half_width(z), bottom.slack(z));
        for (inside, side) in insides.iter().zip([1.0, -1.0]) {
            narrow(&mut points, axis, side, inside, kept, below);
        }
        // The girth the drawn-back sides lost, given back beside them.
        let half = half(&points);
        points = with_girth(&points, centre.y, girth, preserve, |p| lateral(p, axis, half));
    }
    let chords: Vec<(usize, usize)> = insides
        .iter()
        .zip([1.0, -1.0])
        .filter_map(|(f, side)| chord_ends(&points, axis, side, f))
        .collect();
    if chords.is_empty() {
        return TorsoRing::from_rays(&level);
    }
    TorsoRing::with_corners(points, z, centre, axis, &chords)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::body::regions::Region;
    use crate::shape::symmetry::axial;
    use std::f64::consts::TAU;

    #[test]
    fn the_corners_come_back_on_the_plates_with_the_girth_kept() {
        // An ellipse 260 x 180 mm cut by two upright plates at x = +-100 mm, made symmetric by
        // rays: the corners where the plates meet the ellipse lie at y = +-90 sqrt(1 - (100/130)^2).
        let layer = cut_ellipse(130.0, 90.0, 50.0);
        let girth = layer.tape_girth;
        let plate = |x: f64, side: f64| {
            Armhole::through(DVec3::new(x, 0.0, 0.0), DVec3::new(x, 0.0, 100.0), DVec3::NEG_Y, side)
        };
        let (left, right) = (plate(100.0, 1.0), plate(-100.0, -1.0));
        let rimmed = rim(&layer, 0.0, [&left, &right], Preserve::Tape, None);

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

    #[test]
    fn the_girth_a_cut_takes_is_given_back_beside_the_plates() {
        // The plates 5 mm inside the layer's cut sides: cutting again takes girth, and it is
        // given back at the sides; the front and back stay where the layer has them
        // (stretched whole, they stood out as a line across the back).
        let layer = cut_ellipse(130.0, 90.0, 50.0);
        let plate = |x: f64, side: f64| {
            Armhole::through(DVec3::new(x, 0.0, 0.0), DVec3::new(x, 0.0, 100.0), DVec3::NEG_Y, side)
        };
        let (left, right) = (plate(95.0, 1.0), plate(-95.0, -1.0));
        let rimmed = rim(&layer, 0.0, [&left, &right], Preserve::Tape, None);
        let flat: Vec<DVec2> = rimmed.points.iter().map(|p| p.truncate()).collect();
        let girth = Contour { points: flat.clone() }.tape_girth();
        assert!((girth - layer.tape_girth).abs() < 1e-6, "{girth} against {}", layer.tape_girth);
        // Where a ring crosses the midline x = 0, front to back.
        let middle = |points: &[DVec2]| -> Vec<f64> {
            let n = points.len();
            let mut ys: Vec<f64> = (0..n)
                .filter_map(|k| {
                    let (a, b) = (points[k], points[(k + 1) % n]);
                    (a.x > 0.0 && b.x <= 0.0 || a.x <= 0.0 && b.x > 0.0)
                        .then(|| a.y + (b.y - a.y) * a.x / (a.x - b.x))
                })
                .collect();
            ys.sort_by(f64::total_cmp);
            ys
        };
        let (kept, own) = (middle(&flat), middle(&layer.points));
        assert_eq!((kept.len(), own.len()), (2, 2), "the front and the back");
        for (a, b) in kept.iter().zip(&own) {
            assert!((a - b).abs() < 1e-9, "the midline moved from {b} to {a}");
        }
    }

    /// The symmetric layer at height `z` of an ellipse `a` x `b` (semi-axes, mm) cut at
    /// x = +-100 mm, with its tape girth.
    fn cut_ellipse(a: f64, b: f64, z: f64) -> Layer {
        let ellipse = Contour {
            points: (0..2000)
                .map(|k| DVec2::new(a, b) * DVec2::from_angle(TAU * k as f64 / 2000.0))
                .collect(),
        };
        let ring = axial::symmetrize(&ellipse.clip_x(-100.0, 100.0), 0.0, 360, Preserve::Tape);
        let ring = ring.unwrap();
        let girth = Contour { points: ring.points.clone() }.tape_girth();
        Layer {
            region: Region::Torso,
            z,
            centre: ring.centre.to_array(),
            points: ring.points,
            input_tape_girth: girth,
            input_contour_length: girth,
            tape_girth: girth,
            contour_length: girth,
        }
    }

    #[test]
    fn the_rims_lower_edge_is_round_with_the_girths_kept() {
        // Upright plates at x = +-100 mm; the layer at z = 40 (95 mm wide each side) does not
        // reach them, those above (130 mm) meet them with chords 115 mm long.
        let plate = |x: f64, side: f64| {
            Armhole::through(DVec3::new(x, 0.0, 0.0), DVec3::new(x, 0.0, 100.0), DVec3::NEG_Y, side)
        };
        let (left, right) = (plate(100.0, 1.0), plate(-100.0, -1.0));
        let layers = [cut_ellipse(95.0, 90.0, 40.0), cut_ellipse(130.0, 90.0, 50.0)];
        let layers = [layers[0].clone(), layers[1].clone(), Layer { z: 60.0, ..layers[1].clone() }];
        let rings = rims(&layers, 0.0, [&left, &right], Preserve::Tape);
        assert!(rings[0].corners.is_none());
        for (ring, layer) in rings.iter().zip(&layers).skip(1) {
            let flat: Vec<DVec2> = ring.points.iter().map(|p| p.truncate()).collect();
            let girth = Contour { points: flat.clone() }.tape_girth();
            assert!((girth - layer.tape_girth).abs() < 1e-6, "{girth} {}", layer.tape_girth);
            for p in &flat {
                assert!(flat.iter().any(|q| (q.x + p.x).abs() < 1e-9 && (q.y - p.y).abs() < 1e-9));
            }
        }
        // The chord on the left plate: the lowest ring keeps 2 x 3 mm of it, the next one
        // (10 mm higher) 2 sqrt(3^2 + 2 x 50 x 10) = 63.5 mm; the layers' chords are 115 mm.
        let chord = |ring: &TorsoRing| {
            let [front, back, ..] = ring.corners.expect("the ring meets the plates");
            (ring.points[back].y - ring.points[front].y, ring.points[front].x)
        };
        let (lowest, x) = chord(&rings[1]);
        assert!((x - 100.0).abs() < 1e-9 && lowest > 0.0, "{lowest} at x = {x}");
        // (stretched front to back with its sides to get back the girth drawing them lost)
        assert!(lowest < 2.0 * BOTTOM_HALF_MM * 1.1, "the lowest chord is {lowest} mm");
        let (next, _) = chord(&rings[2]);
        // At least the parabola's width; the front-to-back stretch that gives the girth back
        // lengthens it (68.1 mm here), by at most a tenth.
        assert!((63.5..63.5 * 1.1).contains(&next), "the next chord is {next} mm");
        // The lowest ring's points drawn back off the plate (deeper inside it than the layer's
        // own ellipse at their front-to-back position, along the side that faces the plate:
        // |y| < 80 mm, short of the back and front where the girth's stretch moves points
        // along the ellipse) lie at most half way to the ring below; and some are drawn.
        let inside_left = |p: DVec2| inside(&left, layers[1].z, p);
        let below: Vec<DVec2> = rings[0].points.iter().map(|p| p.truncate()).collect();
        let own = |y: f64| 100.0 - 130.0 * (1.0 - (y / 90.0).powi(2)).max(0.0).sqrt();
        let drawn: Vec<DVec2> = (rings[1].points.iter().map(|p| p.truncate()))
            .filter(|p| p.x > 0.0 && p.y.abs() < 80.0 && inside_left(*p) > own(p.y).max(0.0) + 1e-6)
            .collect();
        assert!(!drawn.is_empty(), "no point of the lowest ring is drawn back");
        for p in drawn {
            let below = depth_below(&below, 0.0, 1.0, &inside_left, p.y).expect("a ring below");
            let depth = inside_left(p);
            assert!(depth <= BELOW_SHARE * below + 1e-6, "{p} drawn {depth} mm, below {below}");
        }
    }
}
