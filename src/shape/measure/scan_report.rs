//! A scan measured as `dressform measure` reports it: its landmarks and levels (found on it,
//! or carried by the file of a mannequin dressform made), Table 1's girths, the ISO 8559-1
//! dimensions, torso girths at heights asked for, and where a number is unreliable.

use super::{
    BodyDimensions, Girth, Levels, Measurements, Unreliable, contact_warnings, dimensions,
    find_levels, hold_back, hold_back_waist, measure_at, narrowest_above_the_hip, stance, warnings,
};
use crate::body::regions::{BodyRegions, Landmarks, RegionError};
use crate::body::scan::Scan;
use crate::body::segmented_body::SegmentedBody;
use serde::Serialize;

/// What [`measure_scan`] found (the `measure --json` object, documented in docs/measurements.md).
#[derive(Debug, Clone, Serialize)]
pub struct MeasureReport {
    /// The scan's source, as messages name it.
    pub file: String,
    /// Its landmarks.
    pub landmarks: Landmarks,
    /// Its chest, waist and hip levels.
    pub levels: Levels,
    /// Table 1's measurements at those levels.
    pub measurements: Measurements,
    /// The ISO 8559-1 body dimensions.
    pub dimensions: BodyDimensions,
    /// Torso girths at the requested heights (`null` where there is no torso).
    pub at: Vec<Option<Girth>>,
    /// Where a number is unreliable.
    pub warnings: Vec<String>,
    /// The measurements held back as implausible (NaN, `null`, in `dimensions`), each with its
    /// value and the reason ([`super::hold_back`]).
    pub unreliable: Vec<Unreliable>,
}

/// Measures `scan` (canonical frame, smoothed as the caller wants), with the torso girths at
/// the heights `at` (mm). A mannequin dressform made is measured at the levels and with the
/// landmarks its file carries; any other body is segmented and its levels found, a level
/// that fell back to the body's proportions noted among the warnings.
pub fn measure_scan(scan: &Scan, at: &[f64]) -> Result<MeasureReport, RegionError> {
    measure_found(scan, None, at)
}

/// [`measure_scan`] of a scan whose body was segmented already: `regions` are those
/// [`SegmentedBody::find`] finds on it (the mannequin's pipeline found them), not looked for
/// again.
pub fn measure_segmented_scan(
    scan: &Scan,
    regions: &BodyRegions,
    at: &[f64],
) -> Result<MeasureReport, RegionError> {
    measure_found(scan, Some(regions), at)
}

/// [`measure_scan`], with the body's regions when they were found already.
fn measure_found(
    scan: &Scan,
    regions: Option<&BodyRegions>,
    at: &[f64],
) -> Result<MeasureReport, RegionError> {
    let (body, levels, fallbacks) = match scan.carried {
        Some(carried) => {
            (SegmentedBody::armless(&scan.body, carried.landmarks), carried.levels, Vec::new())
        }
        None => {
            let body = match regions {
                Some(regions) => SegmentedBody::with_regions(&scan.body, regions),
                None => SegmentedBody::find(&scan.body)?,
            };
            let found = find_levels(&body);
            (body, found.levels, found.fallbacks)
        }
    };
    let mut measurements = measure_at(&body, &levels);
    let mut dimensions = dimensions(&body, &levels);
    let mut unreliable = hold_back(&mut dimensions);
    // A mannequin's levels are the customer's, carried: not looked for on its own shape.
    if scan.carried.is_none() {
        let narrowest = narrowest_above_the_hip(&body, &levels);
        unreliable.extend(hold_back_waist(&mut dimensions, levels.waist, narrowest));
    }
    if dimensions.waist_girth_mm.is_nan() {
        measurements.waist.tape = f64::NAN;
        measurements.waist.contour = f64::NAN;
    }
    let mut warnings = warnings(&scan.body, &levels);
    warnings.extend(unreliable.iter().map(Unreliable::to_string));
    warnings.extend(contact_warnings(body.landmarks(), &levels));
    if scan.carried.is_none() {
        warnings.extend(stance::warnings(body.landmarks()));
    }
    warnings.extend(fallbacks);
    let at = body
        .torso_sections(at)
        .into_iter()
        .zip(at)
        .map(|(l, &z)| l.map(|c| Girth::of(z, &c)))
        .collect();
    Ok(MeasureReport {
        file: scan.source.display().to_string(),
        landmarks: *body.landmarks(),
        levels,
        measurements,
        dimensions,
        at,
        warnings,
        unreliable,
    })
}
