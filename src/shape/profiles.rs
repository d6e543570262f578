//! `profiles.json`: the symmetric slice profiles of a mannequin — what the robot side consumes.
//!
//! ```json
//! {
//!   "format": "dressform-profiles/1",
//!   "frame": "canonical: mm, Z up, floor at z = 0, +X = subject's left, facing -Y",
//!   "axis_x": 0.0,                    // the symmetry plane x = axis_x
//!   "rays": 360, "preserve": "tape",
//!   "levels": { "chest_mm": .., "waist_mm": .., "hip_mm": .. },   // measurement levels
//!   "landmarks": { "height_mm": .., "crotch_mm": .., "ankle_mm": .., "left_armpit_mm": .., "right_armpit_mm": ..,
//!                  "neck_mm": .., "centre_x_mm": .., "left_armhole": {"armpit_mm": [x, y, z],
//!                  "shoulder_point_mm": [x, y, z], "normal": [x, y, z]}, "right_armhole": .. },
//!   "layers": [                       // legs (left, right), then torso; each bottom to top
//!     { "region": "torso" | "left_leg" | "right_leg",
//!       "z": 812.5, "centre": [x, y],
//!       "points": [[x, y], ...],      // torso: rays-2 points, legs: rays points; counter-
//!                                     // clockwise from above, starting at the front (-Y)
//!       "input_tape_girth": .., "input_contour_length": ..,
//!       "tape_girth": .., "contour_length": .. }
//!   ]
//! }
//! ```
//!
//! Loading ([`Profiles::load`]) refuses a file that would give meaningless set-points, naming
//! every problem by its field (`layers[12].points[40]`): the wrong format, non-finite or
//! farther than [`MAX_COORDINATE_MM`] coordinates, heights, levels and landmarks, layers
//! without points or with fewer than three, point counts that differ within a region,
//! heights out of order within a region, negative or non-finite girths, and a region the
//! form needs with fewer than two layers.

use crate::body::regions::{Landmarks, Region};
use crate::input::{self, InputError};
use crate::messages;
use crate::shape::mannequin::{Layer, Mannequin};
use crate::shape::measure::Levels;
use crate::shape::symmetry::Preserve;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// The format tag of this version.
pub const FORMAT: &str = "dressform-profiles/1";

/// The farthest any coordinate, height or level may lie from the origin, mm: a standing
/// adult fits within 2.5 m, so 5 m leaves room for any offset and still refuses garbage
/// (1e308, a file in metres read as millimetres is fine, one in micrometres is not).
pub const MAX_COORDINATE_MM: f64 = 5000.0;

/// The largest girth a file may give, mm: a circle of radius [`MAX_COORDINATE_MM`].
pub const MAX_GIRTH_MM: f64 = MAX_COORDINATE_MM * std::f64::consts::TAU;

/// The fewest layers of a region the form needs: rings are placed between two layers.
const MIN_LAYERS: usize = 2;

/// The fewest points of a ring.
const MIN_POINTS: usize = 3;

/// The symmetric profiles of a mannequin.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Profiles {
    /// Always [`FORMAT`].
    pub format: String,
    /// The frame the coordinates are in, for people reading the file.
    pub frame: String,
    /// The symmetry plane x = `axis_x` (mm).
    pub axis_x: f64,
    /// Rays per section.
    pub rays: usize,
    /// The girth each layer kept.
    pub preserve: Preserve,
    /// The chest, waist and hip levels (mm).
    pub levels: Levels,
    /// The input body's landmarks.
    pub landmarks: Landmarks,
    /// Every layer: legs (left, right), then torso, each bottom to top.
    pub layers: Vec<ProfileLayer>,
}

/// One layer of [`Profiles`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ProfileLayer {
    /// Torso, left leg or right leg.
    pub region: Region,
    /// Height (mm).
    pub z: f64,
    /// The ray origin.
    pub centre: [f64; 2],
    /// The ring (see the module documentation).
    pub points: Vec<[f64; 2]>,
    /// Tape girth of the input section (mm).
    pub input_tape_girth: f64,
    /// Contour length of the input section (mm).
    pub input_contour_length: f64,
    /// Tape girth of the ring (mm).
    pub tape_girth: f64,
    /// Contour length of the ring (mm).
    pub contour_length: f64,
}

/// A region as the file spells it.
fn region_name(region: Region) -> String {
    serde_json::to_value(region).ok().and_then(|v| v.as_str().map(String::from)).unwrap_or_default()
}

impl From<&Layer> for ProfileLayer {
    fn from(l: &Layer) -> Self {
        ProfileLayer {
            region: l.region,
            z: l.z,
            centre: l.centre,
            points: l.points.iter().map(|p| p.to_array()).collect(),
            input_tape_girth: l.input_tape_girth,
            input_contour_length: l.input_contour_length,
            tape_girth: l.tape_girth,
            contour_length: l.contour_length,
        }
    }
}

impl Profiles {
    /// Reads a profiles file and checks it ([`Profiles::validate`]) for a form that shapes
    /// `regions`.
    pub fn load(path: &Path, regions: &[Region]) -> Result<Self, InputError> {
        Self::parse(&input::read(path)?, path, regions)
    }

    /// Parses the text of a profiles file (read from `path`, named in errors) and checks it
    /// ([`Profiles::validate`]) for a form that shapes `regions`.
    pub fn parse(text: &str, path: &Path, regions: &[Region]) -> Result<Self, InputError> {
        let profiles: Profiles = input::parse(text, path, "profiles")?;
        input::check(path, profiles.validate(regions))?;
        Ok(profiles)
    }

    /// Every problem that would make set-points for a form shaping `regions` meaningless,
    /// each naming its field (see the module documentation).
    pub fn validate(&self, regions: &[Region]) -> Result<(), Vec<String>> {
        let mut problems = Vec::new();
        if self.format != FORMAT {
            problems.push(format!("format: \"{}\", expected \"{FORMAT}\"", self.format));
        }
        let mut place = |field: String, value: f64| {
            if !(value.is_finite() && value.abs() <= MAX_COORDINATE_MM) {
                let value = messages::number(value);
                problems.push(format!("{field}: {value} is not within ±{MAX_COORDINATE_MM} mm"));
            }
        };
        place("axis_x".into(), self.axis_x);
        let Levels { chest, waist, hip } = self.levels;
        for (name, value) in [("chest_mm", chest), ("waist_mm", waist), ("hip_mm", hip)] {
            place(format!("levels.{name}"), value);
        }
        let l = &self.landmarks;
        for (name, value) in [
            ("height_mm", l.height),
            ("crotch_mm", l.crotch),
            ("ankle_mm", l.ankle),
            ("left_armpit_mm", l.left_armpit),
            ("right_armpit_mm", l.right_armpit),
            ("neck_mm", l.neck),
            ("centre_x_mm", l.centre_x),
        ] {
            place(format!("landmarks.{name}"), value);
        }
        for (name, a) in [("left_armhole", &l.left_armhole), ("right_armhole", &l.right_armhole)] {
            for (part, p) in [("armpit_mm", a.armpit), ("shoulder_point_mm", a.shoulder_point)] {
                for (c, v) in p.to_array().into_iter().enumerate() {
                    place(format!("landmarks.{name}.{part}[{c}]"), v);
                }
            }
        }
        for (i, layer) in self.layers.iter().enumerate() {
            place(format!("layers[{i}].z"), layer.z);
            place(format!("layers[{i}].centre[0]"), layer.centre[0]);
            place(format!("layers[{i}].centre[1]"), layer.centre[1]);
            // The first bad point of a layer stands for the others.
            if let Some((k, c, v)) = layer.points.iter().enumerate().find_map(|(k, p)| {
                p.iter()
                    .enumerate()
                    .find(|(_, v)| !(v.is_finite() && v.abs() <= MAX_COORDINATE_MM))
                    .map(|(c, v)| (k, c, *v))
            }) {
                place(format!("layers[{i}].points[{k}][{c}]"), v);
            }
        }
        for (i, layer) in self.layers.iter().enumerate() {
            if layer.points.len() < MIN_POINTS {
                problems.push(format!(
                    "layers[{i}].points: {} points, a ring needs at least {MIN_POINTS}",
                    layer.points.len()
                ));
            }
            for (name, girth) in [
                ("input_tape_girth", layer.input_tape_girth),
                ("input_contour_length", layer.input_contour_length),
                ("tape_girth", layer.tape_girth),
                ("contour_length", layer.contour_length),
            ] {
                if !(girth.is_finite() && (0.0..=MAX_GIRTH_MM).contains(&girth)) {
                    let girth = messages::number(girth);
                    problems.push(format!("layers[{i}].{name}: {girth} is not a girth in mm"));
                }
            }
        }
        problems.extend(self.region_problems(regions));
        if problems.is_empty() { Ok(()) } else { Err(problems) }
    }

    /// Per region: enough layers where the form needs them, equal point counts, heights in
    /// order.
    fn region_problems(&self, regions: &[Region]) -> Vec<String> {
        let mut problems = Vec::new();
        if self.layers.is_empty() {
            problems.push("layers: empty".into());
        }
        let mut seen: Vec<Region> = Vec::new();
        for (i, layer) in self.layers.iter().enumerate() {
            if seen.contains(&layer.region) {
                continue;
            }
            seen.push(layer.region);
            let of_region: Vec<(usize, &ProfileLayer)> =
                self.layers.iter().enumerate().filter(|(_, l)| l.region == layer.region).collect();
            let name = region_name(layer.region);
            let count = layer.points.len();
            for &(k, other) in &of_region[1..] {
                if other.points.len() != count {
                    problems.push(format!(
                        "layers[{k}].points: {} points, the first {name} layer (layers[{i}]) has {count}",
                        other.points.len()
                    ));
                }
            }
            for pair in of_region.windows(2) {
                let ((_, below), (k, above)) = (pair[0], pair[1]);
                if above.z < below.z {
                    problems.push(format!(
                        "layers[{k}].z: {} is below the {name} layer before it ({}): layers go bottom to top",
                        messages::number(above.z),
                        messages::number(below.z)
                    ));
                }
            }
        }
        for &region in regions {
            let count = self.layers.iter().filter(|l| l.region == region).count();
            if count < MIN_LAYERS {
                problems.push(format!(
                    "layers: {count} {} layer(s); the form's rings need at least {MIN_LAYERS}",
                    region_name(region)
                ));
            }
        }
        problems
    }

    /// The profiles of `m`, whose body was measured at `levels`.
    pub fn of(m: &Mannequin, levels: &Levels) -> Self {
        Profiles {
            format: FORMAT.into(),
            frame: "canonical: mm, Z up, floor at z = 0, +X = subject's left, facing -Y".into(),
            axis_x: m.axis,
            rays: m.options.rays,
            preserve: m.options.preserve,
            levels: *levels,
            landmarks: m.landmarks,
            layers: m
                .left_leg
                .iter()
                .chain(&m.right_leg)
                .chain(&m.torso)
                .map(ProfileLayer::from)
                .collect(),
        }
    }
}
