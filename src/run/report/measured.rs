//! The measurement table of the report: the body measured as `dressform measure` measures it
//! ([`crate::shape::measure::measure_scan`]), one row per ISO 8559-1 dimension with its
//! definition, and for each number held back as implausible
//! ([`crate::shape::measure::hold_back`]) "not measured" and the reason, never the number.

use super::definitions::{DEFINITIONS, Definition, unit};
use crate::body::regions::BodyRegions;
use crate::body::scan::Scan;
use crate::shape::measure::{Unreliable, measure_segmented_scan};
use serde_json::Value;

/// Why a value is missing when no plausibility rule held it back: its rule found no place to
/// measure on this body (an arm raised too high to follow, an arm plate that misses the torso).
const NOT_FOUND: &str = "not found on this scan";

/// A body's measurements as the report shows them.
#[derive(Debug, Clone, PartialEq)]
pub struct Measured {
    /// What was measured, for the reader ("the pose-symmetric scan").
    pub body: &'static str,
    /// The ISO 8559-1 dimensions by their names in `measure --json` (the `dimensions` object:
    /// a number, `null` when not measured, or `left`, `right` and `difference`).
    pub dimensions: Value,
    /// The numbers held back, each with its reason.
    pub unreliable: Vec<Unreliable>,
    /// The other warnings on the measurements (a hole at a level, a level taken from the
    /// body's proportions, an arm resting on the torso).
    pub warnings: Vec<String>,
}

/// One value of a row: a number, or why there is none.
#[derive(Debug, Clone, PartialEq)]
pub enum Reading {
    /// Measured (mm, or degrees).
    Number(f64),
    /// Not measured, and why.
    NotMeasured(String),
}

/// A row's values.
#[derive(Debug, Clone, PartialEq)]
pub enum Values {
    /// One value.
    One(Reading),
    /// A value on each side (the subject's left and right) and their difference, left minus
    /// right, when both were measured.
    Sides {
        /// On the subject's left.
        left: Reading,
        /// On the subject's right.
        right: Reading,
        /// Left minus right.
        difference: Option<f64>,
    },
}

/// One row of the measurement table.
#[derive(Debug, Clone, PartialEq)]
pub struct Row {
    /// The measurement.
    pub definition: &'static Definition,
    /// Its unit ("mm", "°").
    pub unit: &'static str,
    /// Its values.
    pub values: Values,
}

impl Row {
    /// Why each value not measured is missing, without repeats (both sides held back for one
    /// reason give it once), with the side it concerns ("left", "right") when only one is.
    pub fn reasons(&self) -> Vec<(Option<&'static str>, String)> {
        match &self.values {
            Values::One(Reading::NotMeasured(why)) => vec![(None, why.clone())],
            Values::One(Reading::Number(_)) => Vec::new(),
            Values::Sides { left, right, .. } => match (left, right) {
                (Reading::NotMeasured(l), Reading::NotMeasured(r)) if l == r => {
                    vec![(None, l.clone())]
                }
                _ => [("left", left), ("right", right)]
                    .into_iter()
                    .filter_map(|(side, reading)| match reading {
                        Reading::NotMeasured(why) => Some((Some(side), why.clone())),
                        Reading::Number(_) => None,
                    })
                    .collect(),
            },
        }
    }
}

impl Measured {
    /// `scan` measured as `dressform measure` measures it, its `regions` those
    /// [`crate::body::segmented_body::SegmentedBody::find`] finds on it (found already, for
    /// the mannequin); `body` says what it is. An error says why it could not be measured.
    pub fn of(scan: &Scan, regions: &BodyRegions, body: &'static str) -> Result<Measured, String> {
        let report = measure_segmented_scan(scan, regions, &[]).map_err(|e| e.to_string())?;
        let dimensions = serde_json::to_value(&report.dimensions).map_err(|e| e.to_string())?;
        // The held-back numbers are among the warnings too; the table gives their reasons.
        let held: Vec<String> = report.unreliable.iter().map(Unreliable::to_string).collect();
        let warnings = report.warnings.into_iter().filter(|w| !held.contains(w)).collect();
        Ok(Measured { body, dimensions, unreliable: report.unreliable, warnings })
    }

    /// One row per measurement of [`DEFINITIONS`] that [`Self::dimensions`] has, in that
    /// order.
    pub fn rows(&self) -> Vec<Row> {
        DEFINITIONS
            .iter()
            .filter_map(|definition| {
                let key = definition.key;
                let reading = |value: &Value, name: &str| match value.as_f64() {
                    Some(v) => Reading::Number(v),
                    None => Reading::NotMeasured(self.reason(name)),
                };
                let values = match self.dimensions.get(key)? {
                    Value::Object(sides) => {
                        let side = |s: &str| {
                            reading(sides.get(s).unwrap_or(&Value::Null), &format!("{key}.{s}"))
                        };
                        let difference = sides.get("difference").and_then(Value::as_f64);
                        Values::Sides { left: side("left"), right: side("right"), difference }
                    }
                    value => Values::One(reading(value, key)),
                };
                Some(Row { definition, unit: unit(key), values })
            })
            .collect()
    }

    /// Why the value named `name` (`wrist_girth_mm.right`) was not measured.
    fn reason(&self, name: &str) -> String {
        match self.unreliable.iter().find(|u| u.measurement == name) {
            Some(held) => held.reason.clone(),
            None => NOT_FOUND.to_string(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    /// Issue 33's wrist: the right held back with its reason, the left kept; a value missing
    /// with no reason is "not found"; both sides held back for one reason give it once.
    #[test]
    fn a_held_back_number_becomes_its_reason() {
        let too_small = "outside 100-250, an adult's range";
        let unlike = "left 400.0 and right 310.0 differ by 25%";
        let measured = Measured {
            body: "the scan",
            dimensions: json!({
                "stature_mm": 1870.0,
                "across_back_mm": null,
                "wrist_girth_mm": { "left": 203.3, "right": null, "difference": null },
                "calf_girth_mm": { "left": null, "right": null, "difference": null },
            }),
            unreliable: vec![
                Unreliable {
                    measurement: "wrist_girth_mm.right".into(),
                    value: 57.7,
                    reason: too_small.into(),
                },
                Unreliable {
                    measurement: "calf_girth_mm.left".into(),
                    value: 400.0,
                    reason: unlike.into(),
                },
                Unreliable {
                    measurement: "calf_girth_mm.right".into(),
                    value: 310.0,
                    reason: unlike.into(),
                },
            ],
            warnings: Vec::new(),
        };
        let rows = measured.rows();
        let keys: Vec<&str> = rows.iter().map(|r| r.definition.key).collect();
        assert_eq!(keys, ["stature_mm", "across_back_mm", "calf_girth_mm", "wrist_girth_mm"]);
        assert_eq!(rows[0].values, Values::One(Reading::Number(1870.0)));
        assert_eq!(rows[1].reasons(), [(None, NOT_FOUND.to_string())]);
        assert_eq!(rows[2].reasons(), [(None, unlike.to_string())]);
        let wrist = Values::Sides {
            left: Reading::Number(203.3),
            right: Reading::NotMeasured(too_small.into()),
            difference: None,
        };
        assert_eq!(rows[3].values, wrist);
        assert_eq!(rows[3].reasons(), [(Some("right"), too_small.to_string())]);
    }
}
