//! Fitting the robotic form to a mannequin: the body level each of the form's rings stands for
//! ([`placement`]), the lifts that bring the rings there ([`heights`], heights first), and the
//! actuator extensions that make each ring take the mannequin's section ([`rings`]: its girth
//! exactly, its shape by least squares, [`least_squares`]), with a fidelity report
//! ([`RingStatus`], [`GirthReach`], the height error and the radial gaps in [`RingFit`]).
//!
//! **Placement rule.** A ring whose description states an `anchor` is set to that body level
//! on the mannequin ([`level`]: the neck landmark; the shoulders two thirds of the way from the
//! armpits to the neck; the chest, waist and hip levels; the fold under the bust; the abdomen
//! midway between waist and hip; the thighs just under the crotch, where the thigh girth is
//! measured); a ring shapes the torso or the leg its `part` names. Every other ring keeps its
//! place between its neighbours: its built height maps piecewise-linearly through the anchored
//! rings'. The lifts then set the rings' heights as close to their levels as the strokes allow
//! (one bounded least-squares problem over all rings); each ring takes the girth of its level's
//! section, and its radial gaps are measured to the mannequin where it stands. The report says
//! how far each ring stands from its level (`offset_mm`, the height error): 0 where the lifts
//! reach, its built height's distance on a form without lifts.
//!
//! **Frame.** The mannequin's symmetry plane is put on the form's (x = 0); both use the
//! canonical frame otherwise (+X = the subject's left, front = -Y).

mod fidelity;
pub mod heights;
mod least_squares;
pub mod outcome;
mod placement;
mod rings;

pub use fidelity::{GirthReach, RingStatus};
pub use least_squares::GAP_RAYS;
pub use outcome::{
    DEFAULT_GIRTH_TOLERANCE_MM, DEFAULT_HEIGHT_TOLERANCE_MM, ShapeOutcome, Targets, Tolerance,
    compare,
};
pub use placement::{RingLevels, SHOULDERS_ABOVE_ARMPITS, UNDER_BUST_BELOW_CHEST, level};
pub use rings::{
    Placement, RingFit, SHAPE_NOTE_MM, Saturation, region_of, ring_girth, ring_skin, section_at,
};

use crate::body::regions::Region;
use crate::form::setpoints::SetPoints;
use crate::shape::profiles::Profiles;
use form_description::FormDescription;
use serde::Serialize;
use std::collections::BTreeMap;

/// The fit of a form to a mannequin.
#[derive(Debug, Clone, Serialize)]
pub struct FormFit {
    /// The form's name.
    pub form: String,
    /// Per ring: where it shapes the mannequin and how well.
    pub rings: Vec<RingFit>,
    /// Extension of every actuator and lift of the form (mm from its retracted end), within
    /// its stroke.
    pub positions_mm: BTreeMap<String, f64>,
    /// Each lift's extension (mm), also in `positions_mm`: how far it raises its rings.
    pub lifts_mm: BTreeMap<String, f64>,
}

impl FormFit {
    /// Rings that cannot reach the mannequin's section (an actuator saturates by at least
    /// [`SHAPE_NOTE_MM`]).
    pub fn saturated(&self) -> impl Iterator<Item = &RingFit> {
        self.rings.iter().filter(|r| !r.saturated.is_empty())
    }

    /// The mannequin's tape girth at every ring that shapes it (ring → mm): what the form
    /// should reach ([`outcome`]). Rings where the mannequin has no section are left out.
    pub fn target_girths(&self) -> BTreeMap<String, f64> {
        self.rings
            .iter()
            .filter(|r| r.mannequin_girth_mm > 0.0)
            .map(|r| (r.ring.clone(), r.mannequin_girth_mm))
            .collect()
    }

    /// The body level of every ring a lift carries (ring → mm above the floor): where its
    /// lifts should bring it ([`outcome`]). A ring without a lift stands where it is built
    /// and is not judged by its height.
    pub fn target_heights(&self) -> BTreeMap<String, f64> {
        let lifted = self.rings.iter().filter(|r| r.lifted);
        lifted.map(|r| (r.ring.clone(), r.mannequin_height_mm)).collect()
    }

    /// The set-point file of the fit, with each ring's target girth and height
    /// ([`Self::target_girths`], [`Self::target_heights`]), so that a drive can tell whether
    /// the form took the shape.
    pub fn setpoints(&self) -> SetPoints {
        SetPoints::new(self.form.clone(), self.positions_mm.clone())
            .with_target_girths(self.target_girths())
            .with_target_heights(self.target_heights())
    }
}

/// Why a fit could not be made.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum FormFitError {
    /// The profiles cannot give set-points (see [`Profiles::validate`]).
    #[error("{}", crate::messages::separated(.0, "; "))]
    Invalid(Vec<String>),
    /// A ring has no actuators.
    #[error("ring {0} has no actuators")]
    EmptyRing(String),
}

/// The mannequin regions `form`'s rings shape, each once.
pub fn regions_of(form: &FormDescription) -> Vec<Region> {
    let mut regions: Vec<Region> = Vec::new();
    for region in form.rings.iter().map(region_of) {
        if !regions.contains(&region) {
            regions.push(region);
        }
    }
    regions
}

/// Fits `form` to the mannequin of `profiles`: every actuator gets an extension within its
/// stroke; mirror pairs get equal extensions.
///
/// ```
/// use dressform::form::form_fit;
/// use dressform::shape::measure::Levels;
/// use dressform::shape::profiles::{FORMAT, ProfileLayer, Profiles};
/// use dressform::body::regions::{Armhole, Landmarks, Region};
/// use dressform::shape::symmetry::Preserve;
/// use glam::DVec3;
/// use std::f64::consts::TAU;
///
/// // The profiles of a round mannequin: a torso from the crotch (790 mm) to the neck (1480 mm)
/// // whose girth runs hip 1000 (at 880 mm), waist 800 (1060), chest 960 (1250), and legs
/// // 90 mm either side of the axis, 480 mm around at the top. Rings start at the front (-Y)
/// // and run counter-clockwise seen from above.
/// let girth = |knots: &[(f64, f64)], z: f64| {
///     let k = knots.windows(2).position(|w| z <= w[1].0).unwrap_or(knots.len() - 2);
///     let ((z0, g0), (z1, g1)) = (knots[k], knots[k + 1]);
///     g0 + (g1 - g0) * (z - z0) / (z1 - z0)
/// };
/// let layer = |region, z: f64, x: f64, around: f64, n: usize| {
///     let r = around / TAU;
///     let at = |k: usize| TAU * k as f64 / n as f64 - TAU / 4.0;
///     let points = (0..n).map(|k| [x + r * at(k).cos(), r * at(k).sin()]).collect();
///     ProfileLayer {
///         region, z, centre: [x, 0.0], points,
///         input_tape_girth: around, input_contour_length: around,
///         tape_girth: around, contour_length: around,
///     }
/// };
/// let torso = [(790.0, 950.0), (880.0, 1000.0), (1060.0, 800.0), (1250.0, 960.0),
///              (1400.0, 900.0), (1480.0, 380.0)];
/// let legs = [(100.0, 220.0), (790.0, 480.0)];
/// let heights = |from: f64, to: f64| (0..=69).map(move |k| from + (to - from) * k as f64 / 69.0);
/// let mut layers = Vec::new();
/// for (region, x) in [(Region::LeftLeg, 90.0), (Region::RightLeg, -90.0)] {
///     layers.extend(heights(100.0, 789.0).map(|z| layer(region, z, x, girth(&legs, z), 72)));
/// }
/// layers.extend(heights(791.0, 1480.0).map(|z| layer(Region::Torso, z, 0.0, girth(&torso, z), 70)));
/// let armhole = |side: f64| {
///     let armpit = DVec3::new(side * 150.0, 0.0, 1300.0);
///     Armhole::through(armpit, armpit + DVec3::new(side * 30.0, 0.0, 110.0), DVec3::NEG_Y, side)
/// };
/// let landmarks = Landmarks {
///     height: 1700.0, crotch: 790.0, ankle: 100.0, left_armpit: 1300.0, right_armpit: 1300.0,
///     neck: 1480.0, centre_x: 0.0, left_armhole: armhole(1.0), right_armhole: armhole(-1.0),
/// };
/// let profiles = Profiles {
///     format: FORMAT.into(), frame: "canonical".into(), axis_x: 0.0, rays: 72,
///     preserve: Preserve::Tape, levels: Levels { chest: 1250.0, waist: 1060.0, hip: 880.0 },
///     landmarks, layers,
/// };
///
/// let form = form_description::reference();
/// let fit = form_fit::fit(&profiles, &form).unwrap();
/// for actuator in &form.actuators {
///     let extension = fit.positions_mm[&actuator.id];
///     assert!((0.0..=actuator.stroke_mm).contains(&extension)); // never beyond the stroke
/// }
/// // The waist ring sits at the waist level and takes the mannequin's girth there (800.8 mm:
/// // the 800 mm circle's, between two layers), within the panels' polygon.
/// let waist = fit.rings.iter().find(|r| r.ring == "waist").unwrap();
/// assert_eq!(waist.mannequin_height_mm, 1060.0);
/// assert!((waist.mannequin_girth_mm - 800.0).abs() < 2.0);
/// assert!((waist.form_girth_mm - waist.mannequin_girth_mm).abs() < 2.0);
/// ```
pub fn fit(profiles: &Profiles, form: &FormDescription) -> Result<FormFit, FormFitError> {
    fit_by(profiles, form, Placement::default())
}

/// [`fit`] with the panels placed by `rule`.
pub fn fit_by(
    profiles: &Profiles,
    form: &FormDescription,
    rule: Placement,
) -> Result<FormFit, FormFitError> {
    profiles.validate(&regions_of(form)).map_err(FormFitError::Invalid)?;
    let levels = RingLevels::new(profiles, form);
    // Heights first: the lifts bring the rings to their levels; then each ring's panels.
    let heights = heights::solve(form, &levels);
    let lifts_mm = heights.lifts_mm;
    let mut positions_mm = lifts_mm.clone();
    let mut fits = Vec::with_capacity(form.rings.len());
    for ring in &form.rings {
        let placed = (levels.of(&ring.name), heights.rings_mm[&ring.name]);
        let (fit, extensions) = rings::fit_ring(profiles, form, ring, placed, rule)?;
        positions_mm.extend(extensions);
        fits.push(fit);
    }
    // Mirror pairs: the mean of the two (on a symmetric mannequin they differ only by rounding
    // and, across two rings such as the thighs, by the least squares' tolerance, 1e-4 mm);
    // mirror lifts share their variable already.
    for a in &form.actuators {
        if let Some(b) = form.mirror_of(&a.id).filter(|b| b.id != a.id) {
            let mean = 0.5 * (positions_mm[&a.id] + positions_mm[&b.id]);
            positions_mm.insert(a.id.clone(), mean);
            positions_mm.insert(b.id.clone(), mean);
        }
    }
    Ok(FormFit { form: form.name.clone(), rings: fits, positions_mm, lifts_mm })
}
