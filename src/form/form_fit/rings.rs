//! Solving one ring: the extensions that make the form's section match the mannequin's.
//!
//! The form's section at extensions `e` is modelled as the skin stretched over its panels: the
//! convex hull of the panels (flat plates of their width, tangential, centred at
//! `centre + (base_radius + e) · direction`). Each actuator's shape target is where its
//! direction meets the mannequin's section (`R`, the farthest crossing); all targets then move
//! by one radial offset `δ`, found by bisection, so that the skin's girth equals the
//! mannequin's tape girth — girth first, shape second. Extensions are clamped to the stroke;
//! an actuator whose target lies beyond it is reported with the excess.

use super::HeightMap;
use crate::body::regions::Region;
use crate::body::slice::{Contour, convex_hull};
use crate::shape::profiles::{ProfileLayer, Profiles};
use crate::shape::symmetry::rays::cast_along;
use form_description::{ActuatorSpec, Anchor, BodyPart, FormDescription, RingSpec};
use glam::DVec2;
use serde::Serialize;
use std::collections::BTreeMap;

/// The smallest shortfall reported as a shape note, mm: below it the gap is within what the
/// mannequin's own surface is known to (a denoised scan's sections to about a millimetre),
/// and listing it would bury the real problems.
pub const SHAPE_NOTE_MM: f64 = 1.0;

/// An actuator that cannot reach its target by at least [`SHAPE_NOTE_MM`].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Saturation {
    /// The actuator.
    pub actuator: String,
    /// How far its target lies beyond its travel (mm): positive past the full stroke (the
    /// mannequin is larger there), negative below the retracted end (smaller).
    pub beyond_mm: f64,
}

/// How one ring fits.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RingFit {
    /// The ring.
    pub ring: String,
    /// The mannequin level it is anchored to, if any.
    pub anchor: Option<Anchor>,
    /// Where the ring is built on the form (mm).
    pub form_height_mm: f64,
    /// The mannequin height it shapes (mm).
    pub mannequin_height_mm: f64,
    /// `form_height_mm - mannequin_height_mm`: how far the ring sits from its level.
    pub offset_mm: f64,
    /// The mannequin's tape girth there (mm); 0 where the mannequin has no section.
    pub mannequin_girth_mm: f64,
    /// The form's girth at the set-points (mm).
    pub form_girth_mm: f64,
    /// The largest distance, along an actuator's direction, between its panel and the
    /// mannequin (mm).
    pub largest_radial_gap_mm: f64,
    /// Actuators that cannot reach their targets by [`SHAPE_NOTE_MM`] or more.
    pub saturated: Vec<Saturation>,
}

/// The mannequin's section (relative to the form's axis) at height `z` in `region`: the blend
/// of the two layers around it (layers of one region have the same number of points).
fn section_at(profiles: &Profiles, region: Region, z: f64) -> Option<Contour> {
    let layers: Vec<&ProfileLayer> =
        profiles.layers.iter().filter(|l| l.region == region).collect();
    let k = layers.windows(2).position(|w| w[0].z <= z && z <= w[1].z)?;
    let (a, b) = (layers[k], layers[k + 1]);
    let t = if b.z > a.z { (z - a.z) / (b.z - a.z) } else { 0.0 };
    let shift = DVec2::new(profiles.axis_x, 0.0);
    let points = a
        .points
        .iter()
        .zip(&b.points)
        .map(|(p, q)| DVec2::from_array(*p).lerp(DVec2::from_array(*q), t) - shift)
        .collect();
    Some(Contour { points })
}

/// The mannequin region a ring shapes, as its description states.
pub fn region_of(ring: &RingSpec) -> Region {
    match ring.part {
        BodyPart::Torso => Region::Torso,
        BodyPart::LeftLeg => Region::LeftLeg,
        BodyPart::RightLeg => Region::RightLeg,
    }
}

/// The girth of the form's skin on `ring` with its actuators at `positions_mm` (id → mm;
/// missing ids count as retracted).
pub fn ring_girth(
    form: &FormDescription,
    ring: &RingSpec,
    positions_mm: &BTreeMap<String, f64>,
) -> f64 {
    let actuators: Vec<&ActuatorSpec> =
        form.actuators.iter().filter(|a| a.ring == ring.name).collect();
    let extensions: Vec<f64> =
        actuators.iter().map(|a| positions_mm.get(&a.id).copied().unwrap_or(0.0)).collect();
    skin_girth(DVec2::from_array(ring.center_mm), &actuators, &extensions)
}

/// Girth of the skin over the panels of `actuators` at `extensions`.
fn skin_girth(centre: DVec2, actuators: &[&ActuatorSpec], extensions: &[f64]) -> f64 {
    let ends: Vec<DVec2> = actuators
        .iter()
        .zip(extensions)
        .flat_map(|(a, e)| {
            let d = DVec2::from_array(a.direction());
            let middle = centre + d * (a.base_radius_mm + e);
            let half = d.perp() * (0.5 * a.panel_width_mm);
            [middle - half, middle + half]
        })
        .collect();
    Contour { points: convex_hull(&ends) }.perimeter()
}

/// Halvings of the common offset's bracket: it starts a few hundred mm wide, and 60 halvings
/// leave it below the resolution of an `f64` of that size (2⁻⁶⁰ · 1000 mm ≈ 1e-15 mm).
const BISECTION_STEPS: usize = 60;
/// How far (mm) the bracket's ends lie beyond the offsets at which every panel is retracted
/// and every panel is at full stroke, so that both ends are strictly outside.
const BRACKET_MARGIN_MM: f64 = 1.0;
/// A form girth within this of the mannequin's (mm) counts as matched: far below the
/// millimetre a denoised mannequin's surface is known to ([`SHAPE_NOTE_MM`]).
const GIRTH_MATCHED_MM: f64 = 0.01;

/// Fits one ring; returns its report and the extensions of its actuators. Steps: place the
/// ring on the mannequin ([`HeightMap`]), take the mannequin's section there, then match its
/// girth ([`Panels::match_girth`]); a ring with no section stays retracted.
pub(super) fn fit_ring(
    profiles: &Profiles,
    form: &FormDescription,
    ring: &RingSpec,
    placement: &HeightMap,
) -> Result<(RingFit, Vec<(String, f64)>), super::FormFitError> {
    let actuators: Vec<&ActuatorSpec> =
        form.actuators.iter().filter(|a| a.ring == ring.name).collect();
    if actuators.is_empty() {
        return Err(super::FormFitError::EmptyRing(ring.name.clone()));
    }
    let z = placement.mannequin_height(ring.height_mm);
    let centre = DVec2::from_array(ring.center_mm);
    let mut report = RingFit::placed(ring, z);
    let extensions = match section_at(profiles, region_of(ring), z) {
        Some(section) => {
            Panels::against(&section, centre, &actuators).match_girth(&section, &mut report)
        }
        // No mannequin there (above the neck, below the legs): the ring stays retracted.
        None => {
            let retracted = vec![0.0; actuators.len()];
            report.form_girth_mm = skin_girth(centre, &actuators, &retracted);
            retracted
        }
    };
    let ids = actuators.iter().map(|a| a.id.clone());
    Ok((report, ids.zip(extensions).collect()))
}

impl RingFit {
    /// The report of `ring` placed at mannequin height `z`, before it is shaped: no girths,
    /// no gap, nothing saturated.
    fn placed(ring: &RingSpec, z: f64) -> Self {
        RingFit {
            ring: ring.name.clone(),
            anchor: ring.anchor,
            form_height_mm: ring.height_mm,
            mannequin_height_mm: z,
            offset_mm: ring.height_mm - z,
            mannequin_girth_mm: 0.0,
            form_girth_mm: 0.0,
            largest_radial_gap_mm: 0.0,
            saturated: Vec::new(),
        }
    }
}

/// A ring's panels against the mannequin's section: where each actuator's direction meets it.
struct Panels<'a> {
    centre: DVec2,
    actuators: &'a [&'a ActuatorSpec],
    /// Distance from the ring's axis to the section along each actuator's direction.
    reach: Vec<f64>,
}

impl<'a> Panels<'a> {
    /// The panels of `actuators` around `centre`, against `section` (the farthest crossing
    /// along each actuator's direction).
    fn against(section: &Contour, centre: DVec2, actuators: &'a [&'a ActuatorSpec]) -> Self {
        let directions: Vec<DVec2> =
            actuators.iter().map(|a| DVec2::from_array(a.direction())).collect();
        Panels { centre, reach: cast_along(section, centre, &directions), actuators }
    }

    /// The extensions whose skin takes the section's tape girth — girth first, shape second —
    /// filling in `report`'s girths, largest gap and saturated actuators.
    fn match_girth(&self, section: &Contour, report: &mut RingFit) -> Vec<f64> {
        let target = section.tape_girth();
        let delta = self.offset_for_girth(target);
        let extensions = self.clamped(delta);
        report.mannequin_girth_mm = target;
        report.form_girth_mm = skin_girth(self.centre, self.actuators, &extensions);
        report.largest_radial_gap_mm = self.largest_gap(&extensions);
        // Where the girth is matched, the excess is measured at the solution; where the girth
        // is out of reach, at the shape targets themselves (no common offset).
        let matched = (report.form_girth_mm - target).abs() < GIRTH_MATCHED_MM;
        report.saturated = self.saturations(if matched { delta } else { 0.0 });
        extensions
    }

    /// The extensions that put every panel on the section, moved out by `delta` (unclamped).
    fn raw(&self, delta: f64) -> Vec<f64> {
        self.actuators.iter().zip(&self.reach).map(|(a, r)| r - a.base_radius_mm + delta).collect()
    }

    /// [`raw`](Self::raw) within each actuator's stroke.
    fn clamped(&self, delta: f64) -> Vec<f64> {
        let raw = self.raw(delta);
        raw.iter().zip(self.actuators).map(|(e, a)| e.clamp(0.0, a.stroke_mm)).collect()
    }

    /// The common radial offset whose clamped extensions give the skin `target` girth
    /// (bisection); the bracket's end when the girth is out of reach.
    fn offset_for_girth(&self, target: f64) -> f64 {
        let girth = |delta: f64| skin_girth(self.centre, self.actuators, &self.clamped(delta));
        // Bracket: below `lo` every panel is retracted, above `hi` every panel is at full stroke.
        let on_section =
            || self.actuators.iter().zip(&self.reach).map(|(a, r)| r - a.base_radius_mm);
        let longest_stroke = self.actuators.iter().map(|a| a.stroke_mm).fold(0.0, f64::max);
        let (mut lo, mut hi) = (
            -on_section().fold(f64::NEG_INFINITY, f64::max) - BRACKET_MARGIN_MM,
            longest_stroke - on_section().fold(f64::INFINITY, f64::min) + BRACKET_MARGIN_MM,
        );
        if girth(hi) <= target {
            return hi;
        }
        if girth(lo) >= target {
            return lo;
        }
        for _ in 0..BISECTION_STEPS {
            let mid = 0.5 * (lo + hi);
            if girth(mid) < target { lo = mid } else { hi = mid }
        }
        0.5 * (lo + hi)
    }

    /// The largest distance between a panel at `extensions` and the section, along its
    /// actuator's direction.
    fn largest_gap(&self, extensions: &[f64]) -> f64 {
        self.actuators
            .iter()
            .zip(&self.reach)
            .zip(extensions)
            .map(|((a, r), e)| (a.base_radius_mm + e - r).abs())
            .fold(0.0, f64::max)
    }

    /// The actuators whose target at offset `delta` lies [`SHAPE_NOTE_MM`] or more beyond
    /// their travel.
    fn saturations(&self, delta: f64) -> Vec<Saturation> {
        self.actuators
            .iter()
            .zip(self.raw(delta))
            .filter_map(|(a, e)| {
                let beyond = if e > a.stroke_mm { e - a.stroke_mm } else { e.min(0.0) };
                (beyond.abs() >= SHAPE_NOTE_MM)
                    .then(|| Saturation { actuator: a.id.clone(), beyond_mm: beyond })
            })
            .collect()
    }
}
