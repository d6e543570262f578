//! Fitting the robotic form to a mannequin: where each of the form's rings meets the mannequin
//! ([`placement`]), and the actuator extensions that make each ring take the mannequin's
//! section ([`rings`]), with a fidelity report.
//!
//! **Placement rule.** Rings named `neck`, `chest`, `waist` and `hip` are anchored to the
//! mannequin's neck landmark and chest, waist and hip levels. Every other ring keeps its place
//! between its neighbours: its height maps piecewise-linearly through the anchors (below the
//! lowest anchor and above the highest, with the nearest segment's scale). The reference form
//! has no height adjustment, so each ring stays where it is built; the report says how far it
//! sits from the mannequin level it shapes (`offset_mm`).
//!
//! **Frame.** The mannequin's symmetry plane is put on the form's (x = 0); both use the
//! canonical frame otherwise (+X = the subject's left, front = -Y).

mod placement;
mod rings;

pub use placement::{Anchor, Placement};
pub use rings::{RingFit, Saturation, region_of, ring_girth};

use crate::profiles::Profiles;
use serde::Serialize;
use sim::form::FormDescription;
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
    /// Rings that cannot reach the mannequin's section (an actuator saturates).
    pub fn saturated(&self) -> impl Iterator<Item = &RingFit> {
        self.rings.iter().filter(|r| !r.saturated.is_empty())
    }
}

/// Why a fit could not be made.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum FitError {
    /// The profiles have no layers.
    #[error("the profiles have no layers")]
    NoLayers,
    /// A ring has no actuators.
    #[error("ring {0} has no actuators")]
    EmptyRing(String),
}

/// Fits `form` to the mannequin of `profiles`: every actuator gets an extension within its
/// stroke; mirror pairs get equal extensions.
pub fn fit(profiles: &Profiles, form: &FormDescription) -> Result<Fit, FitError> {
    if profiles.layers.is_empty() {
        return Err(FitError::NoLayers);
    }
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
