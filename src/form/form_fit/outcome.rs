//! Did the form take the shape? After a move, each ring's girth is computed from the
//! positions its actuators really reached (the skin over the panels, as in [`ring_girth`])
//! and compared with the mannequin's tape girth there. A ring off by more than the tolerance
//! is "not reached by N mm" — whether a stroke ran out, a set-point was clamped or an
//! actuator fell short — and the whole result says the form could not take the shape.
//!
//! The mannequin's girths come from the fit ([`super::FormFit::target_girths`]): `run` and `demo`
//! have it, and `setpoints` records it in the set-point file (`target_girths_mm`), so that
//! `drive` can check a file made earlier.

use std::collections::BTreeMap;

use form_description::FormDescription;
use serde::Serialize;

use super::ring_girth;
use crate::messages;

/// The default tolerance between a ring's reached girth and the mannequin's, mm: well
/// inside the 9 mm ISO 20685-1 allows between a scan-derived large girth and a tape measure,
/// so a ring within it fits like the customer.
pub const DEFAULT_GIRTH_TOLERANCE_MM: f64 = 5.0;

/// One ring's result.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct RingOutcome {
    /// The ring.
    pub ring: String,
    /// The mannequin's tape girth there, mm.
    pub target_mm: f64,
    /// The form's girth at the reached positions, mm.
    pub reached_mm: f64,
}

impl RingOutcome {
    /// `reached - target`, mm.
    pub fn error_mm(&self) -> f64 {
        self.reached_mm - self.target_mm
    }
}

/// Every ring's result, with the tolerance it was judged by.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ShapeOutcome {
    /// Rings with a mannequin girth, in the form's order.
    pub rings: Vec<RingOutcome>,
    /// The tolerance, mm.
    pub tolerance_mm: f64,
}

impl ShapeOutcome {
    /// Whether `ring` is within tolerance.
    pub fn reached(&self, ring: &RingOutcome) -> bool {
        ring.error_mm().abs() <= self.tolerance_mm
    }

    /// The rings off by more than the tolerance.
    pub fn missed(&self) -> impl Iterator<Item = &RingOutcome> {
        self.rings.iter().filter(|r| !self.reached(r))
    }

    /// A ring's status in words: `ok` or `not reached by 70 mm`.
    pub fn status(&self, ring: &RingOutcome) -> String {
        if self.reached(ring) {
            "ok".into()
        } else {
            format!("not reached by {} mm", whole_mm(ring.error_mm().abs()))
        }
    }

    /// One line for a form that did not take the shape (`None` when every ring is within
    /// tolerance), the rings furthest off first: `waist not reached by 70 mm (625 mm wanted,
    /// 695 reached), hip ... and 3 more`.
    pub fn summary(&self) -> Option<String> {
        let mut missed: Vec<&RingOutcome> = self.missed().collect();
        missed.sort_by(|a, b| b.error_mm().abs().total_cmp(&a.error_mm().abs()));
        (!missed.is_empty()).then(|| {
            let missed = missed.iter().map(|r| {
                let (target, reached) = (whole_mm(r.target_mm), whole_mm(r.reached_mm));
                format!("{} {} ({target} mm wanted, {reached} reached)", r.ring, self.status(r))
            });
            format!(
                "the form could not take the shape (tolerance {} mm): {}",
                messages::number(self.tolerance_mm),
                messages::list(missed)
            )
        })
    }
}

/// A girth in whole millimetres, as messages show it (short whatever its size).
fn whole_mm(mm: f64) -> messages::Number {
    messages::number(mm.round())
}

/// Compares the girth of every ring of `form` named in `targets` (ring → the mannequin's
/// girth, mm) at `positions_mm` (actuator id → reached position; missing ones count as
/// retracted) with its target.
pub fn compare(
    form: &FormDescription,
    positions_mm: &BTreeMap<String, f64>,
    targets: &BTreeMap<String, f64>,
    tolerance_mm: f64,
) -> ShapeOutcome {
    let rings = form
        .rings
        .iter()
        .filter_map(|ring| {
            let &target_mm = targets.get(&ring.name)?;
            let reached_mm = ring_girth(form, ring, positions_mm);
            Some(RingOutcome { ring: ring.name.clone(), target_mm, reached_mm })
        })
        .collect();
    ShapeOutcome { rings, tolerance_mm }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_ring_off_by_more_than_the_tolerance_is_named_with_its_error() {
        let form = form_description::reference();
        let retracted = BTreeMap::new();
        let waist = form.rings.iter().find(|r| r.name == "waist").unwrap();
        let smallest = ring_girth(&form, waist, &retracted);
        let targets: BTreeMap<String, f64> = [("waist".to_string(), smallest - 70.0)].into();
        let outcome = compare(&form, &retracted, &targets, DEFAULT_GIRTH_TOLERANCE_MM);
        assert_eq!(outcome.rings.len(), 1);
        let summary = outcome.summary().unwrap();
        assert!(summary.contains("waist not reached by 70 mm"), "{summary}");
        let near: BTreeMap<String, f64> = [("waist".to_string(), smallest + 4.9)].into();
        assert_eq!(compare(&form, &retracted, &near, 5.0).summary(), None);
    }

    #[test]
    fn a_long_summary_ends_after_a_ring_with_how_many_more() {
        let form = form_description::reference();
        let huge: BTreeMap<String, f64> =
            form.rings.iter().map(|r| (r.name.clone(), 1e308)).collect();
        let summary = compare(&form, &BTreeMap::new(), &huge, 5.0).summary().unwrap();
        assert!(summary.chars().count() <= messages::MAX_LINE, "{summary}");
        assert!(summary.contains("not reached by 1e308 mm (1e308 mm wanted, "), "{summary}");
        let shown = summary.matches(" wanted, ").count();
        assert!(summary.ends_with(&format!(" and {} more", form.rings.len() - shown)), "{summary}");
    }
}
