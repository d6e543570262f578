//! The shoulder cap: above the arm plates the mesh is built from layers bent up over the
//! shoulders, so that the shoulder top is cut across, not along.
//!
//! A horizontal layer meets a nearly level shoulder top at a grazing angle: two layers 6.6 mm
//! apart then differ in width by tens of millimetres, and the band between them is a ledge
//! (square shoulders with steps). Easing the layers' widths hid the ledge but changed their
//! girths and flattened the shoulder's own shape. So from [`ShoulderCap::from`] up to the neck
//! each mesh ring is the section of the body by the surface
//!
//! `z = t + k(t) * max(0, |x - axis| - wing)`
//!
//! — horizontal over the neck and the inner shoulders, rising at slope `k` beyond `wing`
//! (half-way from the neck to the shoulder points). Such a ring crosses the outer shoulder top
//! steeply, so consecutive rings sample it along its own slope, whatever that slope is. `k`
//! grows smoothly from 0 to [`WING_SLOPE`] over [`RAMP_MM`], so the first bent rings continue
//! the horizontal ones below; since `k` never decreases, every surface lies above the one
//! before at every `x`, and the rings never cross. [`ShoulderCap::from`] is the lower shoulder
//! point's height: every bent surface lies above it, so below the shoulder points every
//! horizontal slice of the mesh is a torso layer, girth and all, and the arm plates are cut
//! from horizontal layers only ([`super::arm_plates`]).
//!
//! Each bent section is cut at both armholes (the arm plates) and below the neck, made
//! symmetric as a horizontal section is (paper eq. 5-8) in its projection on the x-y plane —
//! the surface is itself mirror-symmetric, so mirror partners stay at one height — and lifted
//! back onto its surface. Where a bent ring stays within `wing` (the neck) it is the
//! horizontal layer, girth and all. The torso layers ([`super::Mannequin::torso`], the
//! profiles the robotic form copies) stay horizontal with their sections' girths; only the
//! mesh uses the bent rings.

use super::{Layer, MannequinError, MannequinOptions, fairing, smoothstep};
use crate::body::mesh::Mesh;
use crate::body::regions::{Landmarks, Region};
use crate::body::slice::{Contour, sections};
use crate::shape::symmetry::axial;
use glam::{DVec2, DVec3};
use rayon::prelude::*;

/// How steeply a ring rises beyond the wing (rise per mm outward): 45 degrees, so it
/// crosses a level shoulder top at 45 degrees and an average adult's 20-degree shoulder
/// slope at 65.
const WING_SLOPE: f64 = 1.0;

/// Height over which the rings' slope grows from 0 to [`WING_SLOPE`] (mm): four to five
/// layers at the paper's 100 torso layers, so no band between two rings is steep sideways.
const RAMP_MM: f64 = 30.0;

/// Mesh rings in the cap per torso layer: the band between two rings is a chord of the
/// shoulder top, and on a rounded acromion (the generator's random-10) the chord between rings
/// a layer (7.3 mm) apart sagged 5.1 mm under the body's silhouette; half as far apart, it
/// sags a quarter as much.
const RINGS_PER_LAYER: usize = 2;

/// Only points this far inside the wing (mm) are faired ([`super::fairing`]): a ring's point
/// near the wing may lie beyond it on the next ring.
const LEVEL_MARGIN_MM: f64 = 10.0;

/// Heights closer than this are one (mm): a torso layer at the lower shoulder point itself.
const SAME_HEIGHT_MM: f64 = 1e-6;

/// The rings of the mesh from [`ShoulderCap::from`] up to the neck.
pub(super) struct ShoulderCap {
    /// The lowest height at which the rings bend; the torso layers below it are the mesh's
    /// rings as they are.
    pub from: f64,
    /// The bent rings, bottom to top, each with the torso layers' point count (`rays - 2`,
    /// counter-clockwise from above, starting just left of the front midline).
    pub rings: Vec<Vec<DVec3>>,
    /// The centre of the neck cap (on the symmetry plane, at the top ring's height).
    pub neck_centre: DVec3,
}

/// The surface of one bent ring: `z = t + slope * max(0, |x - axis| - wing)`.
#[derive(Debug, Clone, Copy)]
struct Bend {
    t: f64,
    slope: f64,
    axis: f64,
    wing: f64,
}

impl Bend {
    /// How far above `t` the surface lies at `x`.
    fn rise(&self, x: f64) -> f64 {
        self.slope * ((x - self.axis).abs() - self.wing).max(0.0)
    }

    /// The point of the surface above `p`.
    fn lift(&self, p: DVec2) -> DVec3 {
        p.extend(self.t + self.rise(p.x))
    }
}

/// Half the width of a ring about the plane x = `axis`.
fn half_width(points: &[DVec2], axis: f64) -> f64 {
    points.iter().map(|p| (p.x - axis).abs()).fold(0.0, f64::max)
}

/// The bent sections of `body` (the part above the cap's start) on `bends` (all of one
/// slope): each the loop around its `inside` point (or the largest), cut at both armholes and
/// at the neck height, in projection on the x-y plane.
fn bent_sections(body: &Mesh, bends: &[(Bend, DVec2)], lm: &Landmarks) -> Vec<Option<Contour>> {
    let Some(&(first, _)) = bends.first() else { return Vec::new() };
    let sheared = body.map_positions(|p| DVec3::new(p.x, p.y, p.z - first.rise(p.x)));
    let heights: Vec<f64> = bends.iter().map(|(bend, _)| bend.t).collect();
    let cut = sections(&sheared, &heights);
    bends
        .iter()
        .zip(&cut)
        .map(|(&(bend, inside), section)| {
            let around = section.loops.iter().find(|c| c.contains(inside));
            let c = around.or(section.loops.first())?;
            let c = c.keep_where(|p| -lm.left_armhole.beyond(bend.lift(p)));
            let c = c.keep_where(|p| -lm.right_armhole.beyond(bend.lift(p)));
            let c = c.keep_where(|p| lm.neck - bend.lift(p).z);
            (c.points.len() >= 3).then_some(c)
        })
        .collect()
}

/// The heights `t` of the cap's rings, each with a point inside its section: `from`, every
/// torso layer above it and [`RINGS_PER_LAYER`]` - 1` evenly between each two of those
/// (their points inside interpolated).
fn stations(torso: &[Layer], from: f64) -> Vec<(f64, DVec2)> {
    let above = torso.iter().filter(|layer| layer.z >= from);
    let mut ends: Vec<(f64, DVec2)> =
        above.map(|layer| (layer.z, DVec2::from_array(layer.centre))).collect();
    match ends.first() {
        Some(&(z, centre)) if z - from > SAME_HEIGHT_MM => ends.insert(0, (from, centre)),
        _ => {}
    }
    let mut out = Vec::with_capacity(ends.len() * RINGS_PER_LAYER);
    for pair in ends.windows(2) {
        let ((z0, c0), (z1, c1)) = (pair[0], pair[1]);
        out.extend((0..RINGS_PER_LAYER).map(|k| {
            let s = k as f64 / RINGS_PER_LAYER as f64;
            (z0 + (z1 - z0) * s, c0.lerp(c1, s))
        }));
    }
    out.extend(ends.last());
    out
}

/// The shoulder cap of `body` (see the module documentation), whose horizontal torso layers
/// (bottom to top, the last at the neck) are `torso`, about the plane x = `axis`.
pub(super) fn build(
    body: &Mesh,
    lm: &Landmarks,
    torso: &[Layer],
    axis: f64,
    o: &MannequinOptions,
) -> Result<ShoulderCap, MannequinError> {
    let (l, r) = (&lm.left_armhole.shoulder_point, &lm.right_armhole.shoulder_point);
    let shoulder_z = l.z.min(r.z);
    let shoulder_x = 0.5 * ((l.x - axis).abs() + (r.x - axis).abs());
    let neck = torso.last().expect("at least two torso layers");
    let wing = 0.5 * (half_width(&neck.points, axis) + shoulder_x);
    // Every bent ring lies above the lower shoulder point: below it every horizontal slice of
    // the mesh is a torso layer, girth and all.
    let from = shoulder_z;
    let bends: Vec<(Bend, DVec2)> = stations(torso, from)
        .into_iter()
        .map(|(t, inside)| {
            let slope = WING_SLOPE * smoothstep((t - from) / RAMP_MM);
            (Bend { t, slope, axis, wing }, inside)
        })
        .collect();
    let part = body.part(|tri| tri.iter().any(|&v| body.positions[v as usize].z >= from));
    // One shear of the body per slope: the rings above the ramp share one.
    let groups: Vec<&[(Bend, DVec2)]> = bends.chunk_by(|a, b| a.0.slope == b.0.slope).collect();
    let sections: Vec<Option<Contour>> =
        groups.par_iter().flat_map_iter(|group| bent_sections(&part, group, lm)).collect();
    let mut flat = bends
        .iter()
        .zip(sections)
        .map(|(&(bend, _), c)| {
            let missing = MannequinError::MissingLoop { region: Region::Torso, z: bend.t };
            let c = c.ok_or(missing)?;
            let ring = axial::symmetrize(&c, axis, o.rays, o.preserve)?;
            Ok(super::layers::layer(Region::Torso, bend.t, ring.centre, ring.points, &c))
        })
        .collect::<Result<Vec<Layer>, MannequinError>>()?;
    // Faired as the torso layers are where the rings are level (over the neck and the inner
    // shoulders); beyond the wing they cross the shoulder top steeply, one ray's points on
    // neighbouring rings lie on different parts of the shoulder, and averaging them widened
    // the shoulder's width jump by 8-11 mm.
    let level = |p: DVec2| (p.x - axis).abs() < wing - LEVEL_MARGIN_MM;
    fairing::fair(&mut flat, &|_, p| !level(p), o.preserve, true);
    let rings = flat
        .iter()
        .zip(&bends)
        .map(|(ring, (bend, _))| ring.points.iter().map(|&p| bend.lift(p)).collect())
        .collect();
    let neck_centre = DVec3::new(axis, neck.centre[1], neck.z);
    Ok(ShoulderCap { from, rings, neck_centre })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_surface_is_level_within_the_wing_and_mirror_symmetric() {
        let bend = Bend { t: 100.0, slope: 1.0, axis: 10.0, wing: 50.0 };
        assert_eq!(bend.lift(DVec2::new(40.0, 3.0)).z, 100.0);
        assert_eq!(bend.lift(DVec2::new(80.0, 3.0)).z, 120.0);
        assert_eq!(bend.lift(DVec2::new(-60.0, 3.0)).z, 120.0);
    }
}
