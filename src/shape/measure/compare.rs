//! The paper's comparisons: Table 1 (girths of the input and of the symmetric mannequin) and
//! Fig. 11 (the mannequin against bodies made by mirroring the left or the right half).

use super::{Girth, Levels, Measurements, central_loops, measure_at};
use crate::body::segmented_body::SegmentedBody;
use crate::body::slice::{Contour, convex_hull};
use crate::shape::mannequin::Mannequin;
use glam::DVec2;
use serde::Serialize;

/// One row of Table 1.
#[derive(Debug, Clone, Serialize)]
pub struct TableRow {
    /// "chest", "waist" or "hip".
    pub measure: &'static str,
    /// Height of the level (mm).
    #[serde(rename = "z_mm")]
    pub z: f64,
    /// The input's girth.
    pub input: Girth,
    /// The mannequin's girth at the same level.
    pub mannequin: Girth,
    /// Mannequin minus input tape girth (mm).
    pub tape_change_mm: f64,
    /// Mannequin minus input contour length (mm).
    pub contour_change_mm: f64,
}

/// One row of the Fig. 11 comparison.
#[derive(Debug, Clone, Serialize)]
pub struct MirrorRow {
    /// "input", "left-mirrored", "right-mirrored" or "mannequin".
    pub body: &'static str,
    /// Width of the hip section (mm).
    #[serde(rename = "hip_width_mm")]
    pub hip_width: f64,
    /// Chest, waist, hip tape girths (mm).
    #[serde(rename = "chest_mm")]
    pub chest: f64,
    /// Waist tape girth (mm).
    #[serde(rename = "waist_mm")]
    pub waist: f64,
    /// Hip tape girth (mm).
    #[serde(rename = "hip_mm")]
    pub hip: f64,
}

/// Table 1 and Fig. 11 for one input and its mannequin.
#[derive(Debug, Clone, Serialize)]
pub struct Comparison {
    /// The measurement levels (found on the input).
    pub levels: Levels,
    /// The input's measurements.
    pub input: Measurements,
    /// Table 1: chest, waist, hip.
    pub table: Vec<TableRow>,
    /// Fig. 11: input, left-mirrored, right-mirrored, mannequin.
    pub mirrored: Vec<MirrorRow>,
}

/// The section made of the half of `c` on one side of x = `axis` and its mirror image:
/// (tape girth, width).
fn mirrored_half(c: &Contour, axis: f64, left: bool) -> (f64, f64) {
    let half = if left { c.clip_x(axis, f64::INFINITY) } else { c.clip_x(f64::NEG_INFINITY, axis) };
    let mirror = |p: &DVec2| DVec2::new(2.0 * axis - p.x, p.y);
    let all: Vec<DVec2> =
        half.points.iter().copied().chain(half.points.iter().map(mirror)).collect();
    let tape = Contour { points: convex_hull(&all) }.perimeter();
    let reach = half.points.iter().map(|p| (p.x - axis).abs()).fold(0.0, f64::max);
    (tape, 2.0 * reach)
}

fn width(c: &Contour) -> f64 {
    c.bounds().map_or(0.0, |b| b.size().x)
}

/// Compares `body` and its `mannequin` at the body's measurement `levels`.
pub fn compare(body: &SegmentedBody, levels: &Levels, mannequin: &Mannequin) -> Comparison {
    let levels = *levels;
    let input = measure_at(body, &levels);
    let zs = [levels.chest, levels.waist, levels.hip];
    let central = central_loops(&mannequin.mesh, mannequin.axis, &zs);
    let ours: Vec<Girth> = central
        .iter()
        .zip(zs)
        .map(|(c, z)| c.as_ref().map_or(Girth { z, tape: 0.0, contour: 0.0 }, |c| Girth::of(z, c)))
        .collect();
    let names = ["chest", "waist", "hip"];
    let inputs = [input.chest, input.waist, input.hip];
    let table = (0..3)
        .map(|k| TableRow {
            measure: names[k],
            z: zs[k],
            input: inputs[k],
            mannequin: ours[k],
            tape_change_mm: ours[k].tape - inputs[k].tape,
            contour_change_mm: ours[k].contour - inputs[k].contour,
        })
        .collect();

    let loops = body.torso_sections(&zs);
    let empty = Contour::default();
    let at = |k: usize| loops[k].as_ref().unwrap_or(&empty);
    let side = |body: &'static str, left: bool| {
        let g: Vec<(f64, f64)> =
            (0..3).map(|k| mirrored_half(at(k), mannequin.axis, left)).collect();
        MirrorRow { body, hip_width: g[2].1, chest: g[0].0, waist: g[1].0, hip: g[2].0 }
    };
    let hip_of_mannequin = central[2].as_ref().map_or(0.0, width);
    let mirrored = vec![
        MirrorRow {
            body: "input",
            hip_width: width(at(2)),
            chest: inputs[0].tape,
            waist: inputs[1].tape,
            hip: inputs[2].tape,
        },
        side("left-mirrored", true),
        side("right-mirrored", false),
        MirrorRow {
            body: "mannequin",
            hip_width: hip_of_mannequin,
            chest: ours[0].tape,
            waist: ours[1].tape,
            hip: ours[2].tape,
        },
    ];
    Comparison { levels, input, table, mirrored }
}
