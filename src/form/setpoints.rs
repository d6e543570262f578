//! The set-point file: where every actuator of a form should be, in millimetres.
//!
//! ```json
//! {
//!   "format": "dressform-setpoints/1",
//!   "form": "reference",
//!   "positions_mm": { "chest-l1": 23.5, "chest-front": 12.0 },
//!   "target_girths_mm": { "chest": 961.8, "waist": 801.2 },
//!   "target_heights_mm": { "chest": 1224.0, "waist": 1050.0 }
//! }
//! ```
//!
//! * `format` is exactly `dressform-setpoints/1`;
//! * `form` is the `name` of the form description the file was made for;
//! * `positions_mm` maps an actuator id of that form to its extension in mm from the home
//!   (fully retracted) end. Actuators the file leaves out stay where they are;
//! * `target_girths_mm` (optional; `setpoints` and `run` write it) maps a ring of that form
//!   to the mannequin's tape girth the ring should take: after the move `drive` compares
//!   each ring's reached girth with it (`form_fit::outcome`);
//! * `target_heights_mm` (optional, likewise) maps a ring to the body level it stands for
//!   (mm above the floor): after the move `drive` compares the height the form's lifts
//!   reached with it. A lift is an actuator like any other in `positions_mm`.
//!
//! Loading refuses an id given twice (JSON parsers would keep the last silently), an unknown
//! actuator or ring, a non-finite value, a girth that is not positive or beyond
//! [`MAX_GIRTH_MM`], a height outside 0..=[`MAX_COORDINATE_MM`], or another form's
//! name, naming the file and the field or actuator.
//! [`SetPoints::check`] then refuses positions outside `[0, stroke]` with the list of
//! offenders, or clamps them into the stroke and reports them (`--clamp`); only a [`Checked`]
//! set of targets can be driven.

use std::collections::BTreeMap;
use std::path::Path;

use form_description::FormDescription;
use serde::de::{Deserializer, MapAccess, Visitor};
use serde::{Deserialize, Serialize};

use crate::atomic_output::{WriteError, write_atomically};
use crate::form::safety::SafeTarget;
use crate::input::{self, InputError};
use crate::messages;
use crate::shape::profiles::{MAX_COORDINATE_MM, MAX_GIRTH_MM};

/// The `format` of the files this module reads and writes.
pub const FORMAT: &str = "dressform-setpoints/1";

/// A set-point file's content.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SetPoints {
    /// Always [`FORMAT`].
    pub format: String,
    /// The form's name.
    pub form: String,
    /// Actuator id → extension from home, mm.
    #[serde(deserialize_with = "unique_keys")]
    pub positions_mm: BTreeMap<String, f64>,
    /// Ring → the mannequin's tape girth it should take, mm (empty: not recorded).
    #[serde(default, deserialize_with = "unique_keys", skip_serializing_if = "BTreeMap::is_empty")]
    pub target_girths_mm: BTreeMap<String, f64>,
    /// Ring → the body level it should stand at, mm above the floor (empty: not recorded).
    #[serde(default, deserialize_with = "unique_keys", skip_serializing_if = "BTreeMap::is_empty")]
    pub target_heights_mm: BTreeMap<String, f64>,
}

/// A JSON object into a map, refusing a key given twice (by name).
fn unique_keys<'de, D: Deserializer<'de>>(d: D) -> Result<BTreeMap<String, f64>, D::Error> {
    struct Unique;
    impl<'de> Visitor<'de> for Unique {
        type Value = BTreeMap<String, f64>;
        fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
            f.write_str("an object of numbers")
        }
        fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<Self::Value, A::Error> {
            let mut out = BTreeMap::new();
            while let Some((key, value)) = map.next_entry::<String, f64>()? {
                if out.contains_key(&key) {
                    return Err(serde::de::Error::custom(format!("\"{key}\" is given twice")));
                }
                out.insert(key, value);
            }
            Ok(out)
        }
    }
    d.deserialize_map(Unique)
}

/// Positions outside their actuator's stroke, refused.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("positions outside the stroke: {}", list(offending))]
pub struct OutOfStroke {
    /// `(actuator id, asked mm, stroke mm)`, in id order.
    pub offending: Vec<(String, f64, f64)>,
}

fn list(offending: &[(String, f64, f64)]) -> String {
    messages::list(offending.iter().map(|(id, asked, stroke)| {
        let (id, asked, stroke) = (shown(id), messages::number(*asked), messages::number(*stroke));
        format!("{id} asks {asked} mm (stroke 0..={stroke} mm)")
    }))
}

/// An actuator id or ring name as messages show it (escaped, cut: they come from files).
fn shown(id: &str) -> String {
    messages::quote(id.as_bytes(), ID_SHOWN)
}

/// How many characters of an actuator id or ring name a message shows.
const ID_SHOWN: usize = 40;

/// Set-points checked against a form: every target lies within its actuator's stroke.
#[derive(Clone, Debug, PartialEq)]
pub struct Checked {
    /// Actuator id → its target, in id order.
    pub targets: BTreeMap<String, SafeTarget>,
    /// Positions clamped into the stroke (`--clamp`): `(id, asked mm, used mm)`.
    pub clamped: Vec<(String, f64, f64)>,
}

impl SetPoints {
    /// Set-points for the form named `form` (format [`FORMAT`]).
    pub fn new(form: impl Into<String>, positions_mm: BTreeMap<String, f64>) -> Self {
        Self {
            format: FORMAT.to_string(),
            form: form.into(),
            positions_mm,
            target_girths_mm: BTreeMap::new(),
            target_heights_mm: BTreeMap::new(),
        }
    }

    /// The same, with the mannequin's girth each ring should take (ring → mm).
    pub fn with_target_girths(mut self, target_girths_mm: BTreeMap<String, f64>) -> Self {
        self.target_girths_mm = target_girths_mm;
        self
    }

    /// These set-points with the rings' target heights (ring → mm above the floor).
    pub fn with_target_heights(mut self, target_heights_mm: BTreeMap<String, f64>) -> Self {
        self.target_heights_mm = target_heights_mm;
        self
    }

    /// Parses set-point JSON; `path` names the source in errors. Checks the format and that
    /// every value is a finite number; [`SetPoints::validate`] checks it against a form.
    pub fn from_json_str(text: &str, path: &Path) -> Result<Self, InputError> {
        // Non-finite numbers are not JSON; anything else wrong is named by serde.
        let points: SetPoints = input::parse(text, path, "set-point")?;
        if points.format != FORMAT {
            let problem = format!("format: expected \"{FORMAT}\", found \"{}\"", points.format);
            input::check(path, Err(vec![problem]))?;
        }
        Ok(points)
    }

    /// Reads and checks a set-point file against `form` (see [`SetPoints::validate`]).
    pub fn load(path: &Path, form: &FormDescription) -> Result<Self, InputError> {
        let points = Self::from_json_str(&input::read(path)?, path)?;
        input::check(path, points.validate(form))?;
        Ok(points)
    }

    /// Every problem with using these set-points on `form`: another form's name, unknown
    /// actuator (or lift) ids or rings, non-finite values, girths that are not positive or
    /// larger than [`MAX_GIRTH_MM`], heights outside 0..=[`MAX_COORDINATE_MM`].
    pub fn validate(&self, form: &FormDescription) -> Result<(), Vec<String>> {
        let mut problems = Vec::new();
        if self.form != form.name {
            problems.push(format!(
                "form: the file is for \"{}\", the form is \"{}\"",
                self.form, form.name
            ));
        }
        for (id, &mm) in &self.positions_mm {
            if form.axis(id).is_none() {
                problems.push(format!("positions_mm.{}: the form has no actuator", shown(id)));
            } else if !mm.is_finite() {
                problems.push(format!(
                    "positions_mm.{}: {} is not a finite number",
                    shown(id),
                    messages::number(mm)
                ));
            }
        }
        for (ring, &mm) in &self.target_girths_mm {
            let name = shown(ring);
            if !form.rings.iter().any(|r| &r.name == ring) {
                problems.push(format!("target_girths_mm.{name}: the form has no ring \"{name}\""));
            } else if !(mm.is_finite() && mm > 0.0 && mm <= MAX_GIRTH_MM) {
                let (mm, max) = (messages::number(mm), messages::number(MAX_GIRTH_MM));
                problems.push(format!(
                    "target_girths_mm.{name}: {mm} is not a girth in mm (above 0, at most {max})"
                ));
            }
        }
        for (ring, &mm) in &self.target_heights_mm {
            let name = shown(ring);
            if !form.rings.iter().any(|r| &r.name == ring) {
                problems.push(format!("target_heights_mm.{name}: the form has no ring \"{name}\""));
            } else if !(0.0..=MAX_COORDINATE_MM).contains(&mm) {
                let (mm, max) = (messages::number(mm), messages::number(MAX_COORDINATE_MM));
                problems.push(format!(
                    "target_heights_mm.{name}: {mm} is not a height in mm above the floor (0 to {max})"
                ));
            }
        }
        if problems.is_empty() { Ok(()) } else { Err(problems) }
    }

    /// The JSON text of the file (pretty-printed, ending with a newline).
    pub fn to_json_string(&self) -> String {
        let mut text = serde_json::to_string_pretty(self).unwrap_or_default();
        text.push('\n');
        text
    }

    /// Writes the file atomically.
    pub fn save(&self, path: &Path) -> Result<(), WriteError> {
        write_atomically(path, self.to_json_string().as_bytes())
    }

    /// The targets on `form`: every position must lie in `[0, stroke]`, else the offenders
    /// are refused, or clamped into the stroke and listed when `clamp` holds. Unknown ids
    /// and non-finite values (which [`SetPoints::validate`] refuses) are offenders too.
    pub fn check(&self, form: &FormDescription, clamp: bool) -> Result<Checked, OutOfStroke> {
        let mut checked = Checked { targets: BTreeMap::new(), clamped: Vec::new() };
        let mut offending = Vec::new();
        for (id, &asked) in &self.positions_mm {
            let Some(spec) = form.axis(id) else {
                offending.push((id.clone(), asked, f64::NAN));
                continue;
            };
            let stroke = spec.stroke();
            match SafeTarget::within(asked, stroke) {
                Some(target) => {
                    checked.targets.insert(id.clone(), target);
                }
                None if clamp && !asked.is_nan() => {
                    let target = SafeTarget::clamped(asked, stroke);
                    checked.clamped.push((id.clone(), asked, target.mm()));
                    checked.targets.insert(id.clone(), target);
                }
                None => offending.push((id.clone(), asked, stroke.mm())),
            }
        }
        if offending.is_empty() { Ok(checked) } else { Err(OutOfStroke { offending }) }
    }
}
