//! `profiles.json`: the symmetric slice profiles of a mannequin — what the robot side consumes.
//!
//! ```json
//! {
//!   "format": "dressform-profiles/1",
//!   "frame": "canonical: mm, Z up, floor at z = 0, +X = subject's left, facing -Y",
//!   "axis_x": 0.0,                    // the symmetry plane x = axis_x
//!   "rays": 360, "preserve": "tape",
//!   "levels": { "chest": .., "waist": .., "hip": .. },   // measurement levels (mm)
//!   "landmarks": { "height": .., "crotch": .., "ankle": .., "left_armpit": .., "right_armpit": ..,
//!                  "neck": .., "centre_x": .., "left_armhole": {"armpit": [x, y, z],
//!                  "shoulder_point": [x, y, z], "normal": [x, y, z]}, "right_armhole": .. },
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

use crate::mannequin::{Layer, Mannequin};
use crate::measure::Levels;
use crate::regions::{Landmarks, Region};
use crate::symmetry::Preserve;
use serde::{Deserialize, Serialize};

/// The format tag of this version.
pub const FORMAT: &str = "dressform-profiles/1";

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
