//! Fitting the robotic form to a mannequin: where each of the form's rings meets the mannequin
//! ([`placement`]), and the actuator extensions that make each ring take the mannequin's
//! section ([`rings`]), with a fidelity report.
//!
//! **Placement rule.** A ring whose description states an `anchor` (`neck`, `chest`, `waist`,
//! `hip`) is set to the mannequin's neck landmark or its chest, waist or hip level; a ring
//! shapes the torso or the leg its `part` names. Every other ring keeps its place
//! between its neighbours: its height maps piecewise-linearly through the anchors (below the
//! lowest anchor and above the highest, with the nearest segment's scale). The reference form
//! has no height adjustment, so each ring stays where it is built; the report says how far it
//! sits from the mannequin level it shapes (`offset_mm`).
//!
//! **Frame.** The mannequin's symmetry plane is put on the form's (x = 0); both use the
//! canonical frame otherwise (+X = the subject's left, front = -Y).

pub mod outcome;
mod placement;
mod rings;

pub use outcome::{DEFAULT_GIRTH_TOLERANCE_MM, ShapeOutcome, compare};
pub use placement::Placement;
pub use rings::{RingFit, SHAPE_NOTE_MM, Saturation, region_of, ring_girth};

use crate::profiles::Profiles;
use crate::regions::Region;
use crate::setpoints::SetPoints;
use form_description::FormDescription;
use serde::Serialize;
use std::collections::BTreeMap;

/// The fit of a form to a mannequin.
#[derive(Debug, Clone, Serialize)]
pub struct Fit {
    /// The form's name.
    pub form: String,
    /// Per ring: where it shapes the mannequin and how well.
    pub rings: Vec<RingFit>,
    /// Extension of every actuator of the form (mm from its retracted end), within its stroke.
    pub positions_mm: BTreeMap<String, f64>,
}

impl Fit {
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

    /// The set-point file of the fit, with each ring's target girth
    /// ([`Self::target_girths`]), so that a drive can tell whether the form took the shape.
    pub fn setpoints(&self) -> SetPoints {
        SetPoints::new(self.form.clone(), self.positions_mm.clone())
            .with_target_girths(self.target_girths())
    }
}

/// Why a fit could not be made.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum FitError {
    /// The profiles cannot give set-points (see [`Profiles::validate`]).
    #[error("{}", .0.join("; "))]
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
/// use dressform::{fitting, mannequin::MannequinOptions, mesh::Mesh, pipeline, scan};
/// use std::path::Path;
///
/// // A synthetic customer (1700 mm, chest 960, waist 800, hip 1000 mm) taken as a scan, and
/// // the profiles of its symmetric mannequin.
/// let surface = sim::capture::generate(&Default::default()).unwrap().surface;
/// let body = Mesh::new(surface.positions.iter().map(|&p| p.into()).collect(), surface.triangles);
/// let scan = scan::from_mesh(body, Path::new("customer"), &Default::default()).unwrap();
/// let mannequin = pipeline::symmetrize(&scan, &MannequinOptions::default(), |_| {}).unwrap();
///
/// let form = form_description::reference();
/// let fit = fitting::fit(&mannequin.profiles, &form).unwrap();
/// for actuator in &form.actuators {
///     let extension = fit.positions_mm[&actuator.id];
///     assert!((0.0..=actuator.stroke_mm).contains(&extension)); // never beyond the stroke
/// }
/// // The waist ring takes the mannequin's girth there (within the 1 mm a mannequin's surface
/// // is known to, and the panels' polygon).
/// let waist = fit.rings.iter().find(|r| r.ring == "waist").unwrap();
/// assert!((waist.form_girth_mm - waist.mannequin_girth_mm).abs() < 2.0);
/// ```
pub fn fit(profiles: &Profiles, form: &FormDescription) -> Result<Fit, FitError> {
    profiles.validate(&regions_of(form)).map_err(FitError::Invalid)?;
    let placement = Placement::new(profiles, form);
    let mut positions_mm = BTreeMap::new();
    let mut fits = Vec::with_capacity(form.rings.len());
    for ring in &form.rings {
        let (fit, extensions) = rings::fit_ring(profiles, form, ring, &placement)?;
        positions_mm.extend(extensions);
        fits.push(fit);
    }
    // Mirror pairs: the mean of the two (they differ only by rounding on a symmetric mannequin).
    for a in &form.actuators {
        if let Some(b) = form.mirror_of(&a.id).filter(|b| b.id != a.id) {
            let mean = 0.5 * (positions_mm[&a.id] + positions_mm[&b.id]);
            positions_mm.insert(a.id.clone(), mean);
            positions_mm.insert(b.id.clone(), mean);
        }
    }
    Ok(Fit { form: form.name.clone(), rings: fits, positions_mm })
}
