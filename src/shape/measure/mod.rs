//! Body measurements as tailors take them, and the paper's comparisons (Table 1, Fig. 11).
//!
//! Every girth is horizontal and taken on the torso's loop; the tape girth is the convex
//! hull's perimeter. Levels are found on the input body (canonical frame, mm):
//! - **chest** (the bust level; Table 1's chest): at the bust points' level, below the lower
//!   armpit (ISO 8559-1 takes the bust girth horizontally across the bust points; above the
//!   lower armpit a raised arm would join the loop). The bust point is the torso's most forward
//!   level above the fold under the bust, looked for from 10% of the height below the lower
//!   armpit up to [`CHEST_BELOW_ARMPIT_MM`] below it; a chest with no fold at least
//!   [`BUST_FOLD_MM`] deep (a flat or male chest, whose nipples a scan does not show) takes the
//!   nipple line of the standard body proportions, [`BUST_POINT_OF_STATURE`] of the stature.
//!   This is the level the mannequin keeps exactly and the form's chest ring shapes. ISO 8559-1's
//!   **chest girth** is another measurement ([`chest_girth`]): the fullest girth under the
//!   armpits, from the same band up to [`CHEST_TAPE_BELOW_ARMPIT_MM`] under the lower armpit
//!   (and across the bust points where they lie higher);
//! - **hip**: where the buttocks protrude most (the torso's greatest +Y, i.e. backward, extent)
//!   between the crotch and 35% of the way up to the armpits; where they protrude within 1 mm of
//!   that over a range of levels (a flat seat), the middle of that range;
//! - **waist**: the narrowest torso level between 30% and 80% of the way from the hip level to
//!   the chest level; where that band has no narrowest point inside it (a round belly), the
//!   level 55% of the way. (ISO 8559-1 puts the waist midway between the lowest rib and the
//!   iliac crest; a scan has neither landmark, so the narrowing is the evidence used.)
//! - **height** (stature): floor to crown; **crotch height**: the crotch landmark.
//!
//! Scanner noise inflates tape girths (the hull rides on the outermost noise) and heights:
//! the commands that measure denoise the scan first ([`Mesh::taubin_smooth`]).
//!
//! The mannequin is measured at the same levels: it lives in the same frame, so a height on it
//! is the same height on the input.

mod arms;
mod compare;
mod dimensions;
mod neck_and_shoulders;
mod plane;
mod plausibility;
mod scan_report;
pub mod stance;

pub use arms::{ArmMeasures, ArmSection, UPPER_ARM_OF_STATURE, WRIST_FROM_FINGERTIP, arms};
pub use compare::{Comparison, MirrorRow, TableRow, compare};
pub use dimensions::{
    Bilateral, BodyDimensions, KNEE_OF_CROTCH, THIGH_BELOW_CROTCH, dimensions, underbust,
    underbust_band, underbust_fold, underbust_fold_level, underbust_in,
};
pub use neck_and_shoulders::{
    MIDLINE_BAND_MM, NeckAndShoulders, PlaneMeasure, across_back_and_front, neck_and_shoulders,
};
pub use plane::{PlaneLoop, tape_arc};
pub use plausibility::{
    LIMITS, MAX_SIDE_DIFFERENCE, Unreliable, WAIST_OVER_NARROWEST_MM, WRIST_GIRTH_MM, hold_back,
    hold_back_waist, limit,
};
pub use scan_report::{MeasureReport, measure_scan, measure_segmented_scan};

use crate::body::mesh::Mesh;
pub use crate::body::regions::Levels;
use crate::body::regions::{Armhole, Landmarks};
use crate::body::segmented_body::SegmentedBody;
use crate::body::slice::{Contour, sections};
use serde::Serialize;

/// Sampling step when searching for measurement levels (mm).
const LEVEL_STEP_MM: f64 = 2.0;
/// How far below the lower armpit the chest may be (mm): one sampling step, so that the
/// level where the arm joins is never taken. An arm lowered to rest on the torso brings its
/// armpit down to within a few millimetres of the bust point (3 mm on the generator's
/// customers), so a margin of 1% of the stature (17 mm) missed the chest there.
const CHEST_BELOW_ARMPIT_MM: f64 = LEVEL_STEP_MM;
/// How far below the lower armpit the bust point is looked for, as a fraction of the stature.
const BUST_SPAN: f64 = 0.10;
/// How far below the lower armpit the chest girth's tape lies at the least (mm): half the
/// width of a tailor's tape (16 mm: 8 mm) with its upper edge in the armpit, plus how far a
/// found armpit may lie from the body's (up to 15 mm, `tests/segmentation_stances.rs`). Higher,
/// in the armpit itself, the torso's girth grows by 3-4 mm per mm of height (MakeHuman's
/// bodies) and the level would move with the armpit.
pub const CHEST_TAPE_BELOW_ARMPIT_MM: f64 = 25.0;
/// The least depth of the fold under a bust (mm) for the bust point to be found on the body:
/// well above a scanner's noise after smoothing and the 1-5 mm fold of MakeHuman's flat and
/// male chests, whose most forward level wanders by a centimetre with a slight pose.
pub const BUST_FOLD_MM: f64 = 5.0;
/// The hip is looked for from the crotch up this fraction of the way to the lower armpit: the
/// seat (the buttocks' most prominent level) lies in the torso's lowest third, below the
/// waist at about half way.
const HIP_BAND: f64 = 0.35;
/// Where the hip is taken when no torso loop lies in its band, as a fraction of the way from
/// the crotch to the lower armpit: low in the band, where a seat lies.
const HIP_FALLBACK: f64 = 0.15;
/// The waist is looked for between these fractions of the way from the hip level to the
/// chest level: clear of the hip's flare below and the rib cage above.
const WAIST_BAND: (f64, f64) = (0.3, 0.8);
/// Where the waist is taken when the torso has no narrowest level inside its band, as a
/// fraction of the way from the hip to the chest: the natural waist lies at the elbow's level
/// with the arms hanging (0.630 H, Drillis and Contini), about half way between their hip
/// joint (0.530 H) and chest (0.720 H) levels.
const WAIST_FALLBACK: f64 = 0.55;
/// The nipple line as a fraction of the stature (Drillis and Contini's segment proportions,
/// 0.720 H; MakeHuman's bodies have their bust points at 0.71-0.72 H).
pub const BUST_POINT_OF_STATURE: f64 = 0.72;

/// Heights from `lo` to `hi` inclusive, evenly spaced, [`LEVEL_STEP_MM`] apart or closer: the
/// levels a rule searches or a profile joins.
fn heights_between(lo: f64, hi: f64) -> Vec<f64> {
    let count = (((hi - lo).abs() / LEVEL_STEP_MM) as usize).max(1) + 1;
    (0..count).map(|k| lo + (hi - lo) * k as f64 / (count - 1) as f64).collect()
}

/// A horizontal girth.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Girth {
    /// Height (mm).
    #[serde(rename = "z_mm")]
    pub z: f64,
    /// Tape girth: the convex hull's perimeter (mm).
    #[serde(rename = "tape_mm")]
    pub tape: f64,
    /// The contour's own length (mm).
    #[serde(rename = "contour_mm")]
    pub contour: f64,
}

impl Girth {
    pub(crate) fn of(z: f64, c: &Contour) -> Girth {
        Girth { z, tape: c.tape_girth(), contour: c.perimeter() }
    }
}

/// A body's measurements.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Measurements {
    /// Height (mm).
    #[serde(rename = "height_mm")]
    pub height: f64,
    /// Crotch height, the inseam (mm).
    #[serde(rename = "crotch_height_mm")]
    pub crotch_height: f64,
    /// Chest girth.
    pub chest: Girth,
    /// Waist girth.
    pub waist: Girth,
    /// Hip girth.
    pub hip: Girth,
}

/// A body's measurement levels, with a note for each level its rule could not find on the
/// body and took from the body's proportions instead.
#[derive(Debug, Clone, PartialEq)]
pub struct FoundLevels {
    /// The levels.
    pub levels: Levels,
    /// One line per level that fell back to a proportion, saying which and why.
    pub fallbacks: Vec<String>,
}

/// Finds the chest, waist and hip levels of `body` (see the module documentation for the
/// rules).
pub fn levels(body: &SegmentedBody) -> Levels {
    find_levels(body).levels
}

/// [`levels`], with a note for each level that fell back to a proportion of the body.
pub fn find_levels(body: &SegmentedBody) -> FoundLevels {
    let mut fallbacks = Vec::new();
    let m = body.landmarks();
    // Below the lower armpit a raised arm cannot join the torso's loop.
    let armpit = m.left_armpit.min(m.right_armpit);
    let (lo, hi) = (m.crotch + LEVEL_STEP_MM, armpit - LEVEL_STEP_MM);
    let count = (((hi - lo) / LEVEL_STEP_MM) as usize).max(2);
    let zs: Vec<f64> = (0..count).map(|k| lo + (hi - lo) * k as f64 / (count - 1) as f64).collect();
    let loops = body.torso_sections(&zs);
    let samples: Vec<(f64, &Contour)> =
        zs.iter().zip(&loops).filter_map(|(&z, l)| l.as_ref().map(|l| (z, l))).collect();
    let best = |range: (f64, f64), score: &dyn Fn(&Contour) -> f64| {
        samples
            .iter()
            .filter(|(z, _)| *z >= range.0 && *z <= range.1)
            .map(|&(z, c)| (z, score(c)))
            .max_by(|a, b| a.1.total_cmp(&b.1))
    };
    let (chest, chest_note) = chest_level(&samples, armpit, m.height);
    fallbacks.extend(chest_note);
    let hip_band = (m.crotch, m.crotch + HIP_BAND * (armpit - m.crotch));
    let back = |c: &Contour| c.points.iter().map(|p| p.y).fold(f64::NEG_INFINITY, f64::max);
    let hip = match best(hip_band, &back) {
        Some((_, most)) => {
            let seat: Vec<f64> = samples
                .iter()
                .filter(|(z, c)| *z >= hip_band.0 && *z <= hip_band.1 && back(c) >= most - 1.0)
                .map(|(z, _)| *z)
                .collect();
            0.5 * (seat[0] + seat[seat.len() - 1])
        }
        None => {
            let hip = m.crotch + HIP_FALLBACK * (armpit - m.crotch);
            fallbacks.push(format!(
                "the hip level was not found (no torso loop between the crotch and {:.0}% of \
                 the way up to the armpits): it is taken at {:.0}% of the way, z = {hip:.0} mm",
                100.0 * HIP_BAND,
                100.0 * HIP_FALLBACK
            ));
            hip
        }
    };
    let band = (hip + WAIST_BAND.0 * (chest - hip), hip + WAIST_BAND.1 * (chest - hip));
    let narrowest = best(band, &|c| -c.tape_girth()).map(|b| b.0);
    let interior = narrowest.filter(|&z| z > band.0 + LEVEL_STEP_MM && z < band.1 - LEVEL_STEP_MM);
    let waist = interior.unwrap_or_else(|| {
        let waist = hip + WAIST_FALLBACK * (chest - hip);
        fallbacks.push(format!(
            "the waist level was not found (the torso narrows to the edge of its band, {:.0} to \
             {:.0} mm, with no narrowest level inside): it is taken {:.0}% of the way from the \
             hip to the chest, z = {waist:.0} mm",
            band.0,
            band.1,
            100.0 * WAIST_FALLBACK
        ));
        waist
    });
    FoundLevels { levels: Levels { chest, waist, hip }, fallbacks }
}

/// ISO 8559-1's chest girth and its level: the fullest horizontal tape girth under the
/// armpits, among the torso's levels from [`BUST_SPAN`] of the stature below the lower armpit up
/// to [`CHEST_TAPE_BELOW_ARMPIT_MM`] below it, and the bust level of `levels` (the tape passes
/// across the bust points, even where they lie that close under the armpit). `None` where the
/// torso has no loop there.
pub fn chest_girth(body: &SegmentedBody, levels: &Levels) -> Option<Girth> {
    let m = body.landmarks();
    let armpit = m.left_armpit.min(m.right_armpit);
    let top = (armpit - CHEST_TAPE_BELOW_ARMPIT_MM).max(levels.chest);
    let mut zs = heights_between(armpit - BUST_SPAN * m.height, top);
    zs.push(levels.chest);
    let loops = body.torso_sections(&zs);
    zs.iter()
        .zip(&loops)
        .filter_map(|(&z, l)| l.as_ref().map(|c| Girth::of(z, c)))
        .max_by(|a, b| a.tape.total_cmp(&b.tape))
}

/// The torso's narrowest tape girth between the hip level and the fold under the bust (the
/// chest level on a body without one), where it lies strictly inside that span: where the
/// waist's rule should have found the waist. `None` where the torso narrows to either end (a
/// barrel torso, whose waist is taken from a proportion).
pub fn narrowest_above_the_hip(body: &SegmentedBody, levels: &Levels) -> Option<Girth> {
    let top = underbust_fold_level(body, levels).unwrap_or(levels.chest);
    let zs = heights_between(levels.hip, top);
    let loops = body.torso_sections(&zs);
    let girths: Vec<Girth> =
        zs.iter().zip(&loops).filter_map(|(&z, l)| l.as_ref().map(|c| Girth::of(z, c))).collect();
    let k = (0..girths.len()).min_by(|&a, &b| girths[a].tape.total_cmp(&girths[b].tape))?;
    (k > 0 && k + 1 < girths.len()).then_some(girths[k])
}

/// The chest level among `samples` (torso loops by ascending height) below the lower `armpit`
/// of a body `height` tall: see the module documentation.
fn chest_level(samples: &[(f64, &Contour)], armpit: f64, height: f64) -> (f64, Option<String>) {
    let top = armpit - CHEST_BELOW_ARMPIT_MM;
    let band: Vec<(f64, f64)> = samples
        .iter()
        .filter(|(z, _)| *z >= armpit - BUST_SPAN * height && *z <= top)
        .map(|&(z, c)| (z, forward(c)))
        .collect();
    let fronts: Vec<f64> = band.iter().map(|b| b.1).collect();
    match deepest_fold(&fronts, BUST_FOLD_MM) {
        Some((fold, _)) => {
            let above = &band[fold + 1..];
            (above.iter().max_by(|a, b| a.1.total_cmp(&b.1)).map_or(top, |b| b.0), None)
        }
        None => {
            // No bust fold (a flat or male chest): the nipple line's proportion is the rule
            // then, unless the armpits are so low that it lies above them.
            let proportion = BUST_POINT_OF_STATURE * height;
            let note = (proportion > top).then(|| {
                format!(
                    "the chest level was not found: no fold under a bust and the nipple line's \
                     proportion ({BUST_POINT_OF_STATURE} of the height, z = {proportion:.0} mm) \
                     lies above the lower armpit ({armpit:.0} mm): it is taken just below the \
                     armpit, z = {top:.0} mm"
                )
            });
            (proportion.min(top), note)
        }
    }
}

/// How far forward (-Y) the front of a torso loop reaches (mm).
fn forward(c: &Contour) -> f64 {
    -c.points.iter().map(|p| p.y).fold(f64::INFINITY, f64::min)
}

/// The deepest fold in a front profile (`forward` of levels by ascending height): the level set
/// farthest back behind the most forward levels both below and above it, with its depth (mm);
/// `None` when no level is set back more than `min_depth`.
fn deepest_fold(forward: &[f64], min_depth: f64) -> Option<(usize, f64)> {
    let n = forward.len();
    let mut below = vec![f64::MIN; n];
    let mut above = vec![f64::MIN; n];
    for k in 1..n {
        below[k] = below[k - 1].max(forward[k - 1]);
        above[n - 1 - k] = above[n - k].max(forward[n - k]);
    }
    (0..n)
        .map(|k| (k, below[k].min(above[k]) - forward[k]))
        .filter(|&(_, depth)| depth > min_depth)
        .max_by(|a, b| a.1.total_cmp(&b.1))
}

/// Where the girths of `body` at `levels` are unreliable: a hole in the scan crossing a
/// level (its loop is closed with a straight edge across the hole).
pub fn warnings(body: &Mesh, levels: &Levels) -> Vec<String> {
    let names = ["bust", "waist", "hip"];
    sections(body, &[levels.chest, levels.waist, levels.hip])
        .iter()
        .zip(names)
        .filter(|(s, _)| s.bridged_gaps > 0)
        .map(|(s, name)| {
            format!(
                "the {name} girth at z = {:.0} mm crosses {} hole(s) in the scan, bridged with \
                 straight edges: it may read short",
                s.height, s.bridged_gaps
            )
        })
        .collect()
}

/// Where a girth at `levels` is taken across an arm resting on the torso: between where the
/// arm's loop joins the torso's and its armpit ([`crate::body::regions::Contact`]) the torso is cut
/// off the arm along the crease between them, where a tape passed under the arm would lie,
/// but the arm may press the torso in there.
pub fn contact_warnings(landmarks: &Landmarks, levels: &Levels) -> Vec<String> {
    let sides = [("left", &landmarks.left_armhole), ("right", &landmarks.right_armhole)];
    let resting = sides
        .into_iter()
        .filter_map(|(side, a): (_, &Armhole)| a.contact.map(|c| (side, c.from, a.armpit.z)));
    let mut out = Vec::new();
    for (side, from, armpit) in resting {
        for (name, z) in [("bust", levels.chest), ("waist", levels.waist), ("hip", levels.hip)] {
            if (from..armpit).contains(&z) {
                out.push(format!(
                    "the {side} arm rests on the torso from {from:.0} to {armpit:.0} mm: the \
                     {name} girth at z = {z:.0} mm is cut off the arm along the crease between \
                     them; scan with the arms 10 degrees or more from the body for a girth \
                     clear of the arm"
                ));
            }
        }
    }
    out
}

/// Measures `body` at `levels`, on its torso's loops.
pub fn measure_at(body: &SegmentedBody, levels: &Levels) -> Measurements {
    let zs = [levels.chest, levels.waist, levels.hip];
    let loops = body.torso_sections(&zs);
    let girth = |k: usize| {
        loops[k]
            .as_ref()
            .map_or(Girth { z: zs[k], tape: 0.0, contour: 0.0 }, |c| Girth::of(zs[k], c))
    };
    Measurements {
        height: body.landmarks().height,
        crotch_height: body.landmarks().crotch,
        chest: girth(0),
        waist: girth(1),
        hip: girth(2),
    }
}

/// The loop around the symmetry plane x = `axis` at each height, for a mesh with no arms or
/// head (the mannequin): `None` where the plane cuts nothing.
pub fn central_loops(mesh: &Mesh, axis: f64, heights: &[f64]) -> Vec<Option<Contour>> {
    sections(mesh, heights)
        .into_iter()
        .map(|s| {
            let straddles = |c: &&Contour| {
                c.points.iter().any(|p| p.x >= axis) && c.points.iter().any(|p| p.x <= axis)
            };
            s.loops.iter().find(straddles).cloned()
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::body::regions::Contact;
    use glam::{DVec2, DVec3};

    #[test]
    fn a_girth_across_a_resting_arm_is_warned() {
        let armhole = |side: f64| {
            Armhole::through(
                DVec3::new(side * 150.0, 0.0, 1300.0),
                DVec3::new(side * 190.0, 0.0, 1420.0),
                DVec3::NEG_Y,
                side,
            )
        };
        // The right arm rests on the torso from 1270 mm up to its armpit at 1300 mm.
        let contact = Contact { from: 1270.0, normal: DVec2::NEG_X, offset: 150.0 };
        let landmarks = Landmarks {
            height: 1700.0,
            crotch: 800.0,
            ankle: 90.0,
            left_armpit: 1300.0,
            right_armpit: 1300.0,
            neck: 1450.0,
            centre_x: 0.0,
            left_armhole: armhole(1.0),
            right_armhole: armhole(-1.0).with_contact(contact),
        };
        let at = |chest: f64| Levels { chest, waist: 1050.0, hip: 900.0 };
        assert!(contact_warnings(&landmarks, &at(1260.0)).is_empty(), "below the contact");
        let warned = contact_warnings(&landmarks, &at(1280.0));
        assert_eq!(warned.len(), 1, "{warned:?}");
        assert!(warned[0].contains("right arm rests on the torso from 1270 to 1300 mm"));
        assert!(warned[0].contains("bust girth at z = 1280 mm"), "{}", warned[0]);
    }
}
