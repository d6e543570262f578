//! Garment descriptions: a garment put on the form, per ring a band with its relaxed girth
//! and how it stretches; TOML, validated against the form it is put on. The simulator puts
//! its load on the panels (`form_sim::garment`); the host's fit test reads its girths.
//! [`SHIPPED`] are the example garments in `form-description/garments/`.
//!
//! ```toml
//! name = "jersey top"
//! kind = "daily"                 # "daily" wear or "compression"
//!
//! [[band]]
//! ring = "chest"                 # the form's ring the band lies on
//! relaxed_girth_mm = 880.0       # the garment's girth there, unstretched
//! width_mm = 50.0                # optional: the band's height on the ring (default 50)
//! tension_n_per_m_per_percent = 8.0   # linear stretch: T = k × strain in %
//!
//! [[band]]
//! ring = "waist"
//! relaxed_girth_mm = 760.0
//! # or a measured force-extension curve, strain in % and tension in N/m (EN 14704-1 strip
//! # test force divided by the strip's width), from 0 % up, tension rising:
//! force_extension = [[0.0, 0.0], [10.0, 60.0], [20.0, 150.0], [40.0, 420.0]]
//! ```

use std::collections::HashSet;

use super::description::FormDescription;
use serde::Deserialize;

/// The shipped example garments (`form-description/garments/`), by name, for the reference
/// form and the demo's customer (chest 960, waist 800, hip 1000 mm): a fitted woven dress,
/// the same dress 5% too small at the waist, a jersey top and a compression body.
pub const SHIPPED: [(&str, &str); 4] = [
    ("woven-dress", include_str!("../garments/woven-dress.toml")),
    ("woven-dress-small-waist", include_str!("../garments/woven-dress-small-waist.toml")),
    ("jersey-top", include_str!("../garments/jersey-top.toml")),
    ("compression-garment", include_str!("../garments/compression-garment.toml")),
];

/// A shipped garment's description text, by name.
pub fn shipped(name: &str) -> Option<&'static str> {
    SHIPPED.iter().find(|(n, _)| *n == name).map(|(_, text)| *text)
}

/// How tall a band is on its ring when the description does not say, mm: the height of the
/// garment a ring's panels carry, about the spacing of a dress form's measurement levels
/// (the reference form's rings are 45-125 mm apart).
pub const DEFAULT_BAND_WIDTH_MM: f64 = 50.0;

/// What a garment is worn for: the comfort bands a fit test judges it by.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum GarmentKind {
    /// Everyday clothing: pressure comfort bands for daily wear.
    #[default]
    Daily,
    /// A compression garment: classes of RAL-GZ 387.
    Compression,
}

/// A garment: its bands on the form's rings.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GarmentSpec {
    /// A name for people.
    pub name: String,
    /// What it is worn for.
    #[serde(default)]
    pub kind: GarmentKind,
    /// Its bands (`[[band]]`), at most one per ring.
    #[serde(rename = "band", default)]
    pub bands: Vec<BandSpec>,
}

/// The garment around one ring of the form.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BandSpec {
    /// The form's ring.
    pub ring: String,
    /// The garment's girth there, unstretched, mm.
    pub relaxed_girth_mm: f64,
    /// The band's height on the ring, mm.
    #[serde(default = "default_width")]
    pub width_mm: f64,
    /// Linear stretch: tension per unit width per percent of strain, N/m per %.
    #[serde(default)]
    pub tension_n_per_m_per_percent: Option<f64>,
    /// A measured curve: (strain %, tension N/m) from 0 % up.
    #[serde(default)]
    pub force_extension: Option<Vec<[f64; 2]>>,
}

fn default_width() -> f64 {
    DEFAULT_BAND_WIDTH_MM
}

/// How a band stretches: its tension (N per metre of width) at a strain.
#[derive(Clone, Debug, PartialEq)]
pub enum Stretch {
    /// `T = k × strain %`.
    Linear {
        /// N/m per %.
        n_per_m_per_percent: f64,
    },
    /// Linear between measured (strain %, N/m) points, the last segment's slope beyond them.
    Measured {
        /// The points, strain rising from 0.
        points: Vec<[f64; 2]>,
    },
}

impl Stretch {
    /// The tension at `strain_percent` (N/m); 0 for a band not stretched.
    pub fn tension(&self, strain_percent: f64) -> f64 {
        if strain_percent <= 0.0 {
            return 0.0;
        }
        match self {
            Stretch::Linear { n_per_m_per_percent } => n_per_m_per_percent * strain_percent,
            Stretch::Measured { points } => {
                let k =
                    points.partition_point(|p| p[0] < strain_percent).clamp(1, points.len() - 1);
                let ([s0, t0], [s1, t1]) = (points[k - 1], points[k]);
                t0 + (strain_percent - s0) * (t1 - t0) / (s1 - s0)
            }
        }
    }
}

impl BandSpec {
    /// Its stretch (the description is validated: exactly one of the two is given).
    pub fn stretch(&self) -> Stretch {
        match (&self.force_extension, self.tension_n_per_m_per_percent) {
            (Some(points), _) => Stretch::Measured { points: points.clone() },
            (None, k) => Stretch::Linear { n_per_m_per_percent: k.unwrap_or(0.0) },
        }
    }
}

/// Why a garment description cannot be used.
#[derive(Debug, thiserror::Error)]
pub enum GarmentError {
    /// Not TOML, or not a garment's fields (the parser names the line and field).
    #[error("{0}")]
    Toml(#[from] toml::de::Error),
    /// Well-formed but unusable: every problem, one per line.
    #[error("invalid garment description:{}", .0.iter().map(|p| format!("\n  - {p}")).collect::<String>())]
    Invalid(Vec<String>),
}

impl GarmentSpec {
    /// Parses a garment description and checks it against `form` ([`Self::problems`]).
    pub fn from_toml_str(text: &str, form: &FormDescription) -> Result<Self, GarmentError> {
        let spec: GarmentSpec = toml::from_str(text)?;
        let problems = spec.problems(form);
        if problems.is_empty() { Ok(spec) } else { Err(GarmentError::Invalid(problems)) }
    }

    /// Every problem, each naming the band and field: no band, a ring the form lacks or given
    /// twice, a girth or width that is not a positive finite length, a stretch given both ways
    /// or neither, a negative or non-finite slope, a curve that does not start at 0 %, whose
    /// strain does not rise or whose tension falls.
    pub fn problems(&self, form: &FormDescription) -> Vec<String> {
        let mut problems = Vec::new();
        if self.bands.is_empty() {
            problems.push("no `[[band]]`: a garment needs at least one".into());
        }
        let mut seen = HashSet::new();
        for band in &self.bands {
            let mut problem = |what: String| problems.push(format!("band `{}`: {what}", band.ring));
            if form.ring(&band.ring).is_none() {
                problem(format!("the form \"{}\" has no ring `{}`", form.name, band.ring));
            } else if !seen.insert(band.ring.as_str()) {
                problem("given twice".into());
            }
            for (field, value) in
                [("relaxed_girth_mm", band.relaxed_girth_mm), ("width_mm", band.width_mm)]
            {
                if !(value.is_finite() && value > 0.0) {
                    problem(format!("`{field}` = {value} must be a length above 0"));
                }
            }
            match (&band.force_extension, band.tension_n_per_m_per_percent) {
                (Some(_), Some(_)) | (None, None) => problem(
                    "give its stretch as `tension_n_per_m_per_percent` or `force_extension`, \
                     one of the two"
                        .into(),
                ),
                (None, Some(k)) if !(k.is_finite() && k >= 0.0) => {
                    problem(format!("`tension_n_per_m_per_percent` = {k} must be 0 or more"));
                }
                (Some(points), None) => {
                    if let Some(why) = curve_problem(points) {
                        problem(format!("`force_extension`: {why}"));
                    }
                }
                _ => {}
            }
        }
        problems
    }
}

/// What makes a force-extension curve unusable, if anything.
fn curve_problem(points: &[[f64; 2]]) -> Option<String> {
    if points.len() < 2 {
        return Some("needs at least two points".into());
    }
    if points.iter().flatten().any(|v| !v.is_finite()) {
        return Some("every strain and tension must be a finite number".into());
    }
    if points[0] != [0.0, 0.0] {
        return Some("must start at [0, 0] (no tension unstretched)".into());
    }
    for pair in points.windows(2) {
        let ([s0, t0], [s1, t1]) = (pair[0], pair[1]);
        if s1 <= s0 {
            return Some(format!("strain must rise ({s0} % then {s1} %)"));
        }
        if t1 < t0 {
            return Some(format!("tension falls from {t0} to {t1} N/m"));
        }
    }
    None
}
