//! Body regions from slices (in the spirit of Ju et al. 2000): the body is sliced every few
//! millimetres and its loops are tracked from level to level, which finds the landmarks where
//! the topology changes — the crotch (two leg loops merge into one), the armpits (arm loops
//! join the torso), the neck (the narrowest torso level below the head) — and labels every
//! loop torso, left/right leg, left/right arm or head.
//!
//! Tracking starts from the torso at 60% of the height (between crotch and armpits for any
//! standing adult) and follows the loop that contains the previous loop's centroid, up and
//! down. The subject's left is +X in the canonical frame. Above the armpits the arms are cut
//! off the torso at the armholes ([`Armhole`]), as a dress form's arm plates cut them.

mod armhole;
mod contact;
mod tracking;

pub use armhole::Armhole;
pub use contact::Contact;

use crate::body::mesh::Mesh;
use crate::body::slice::{Contour, Section, sections};
use glam::DVec2;
use serde::{Deserialize, Serialize};

/// The landmarks' bisections stop when the interval is this short (mm). Each landmark is the
/// top of its last interval, the first height found changed (the legs or an arm joined, the
/// neck under a resting arm opened), so the change may begin up to this far below it
/// ([`tracking`] finds them, an [`Armhole`] cuts from that far below its armpit).
const BISECTION_MM: f64 = 0.1;

/// The part of the body a loop belongs to.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Region {
    /// From the crotch to the neck (above the armpits it includes the shoulders).
    Torso,
    /// The subject's left leg (+X).
    LeftLeg,
    /// The subject's right leg (-X).
    RightLeg,
    /// The subject's left arm and hand, below the armpit.
    LeftArm,
    /// The subject's right arm and hand, below the armpit.
    RightArm,
    /// Above the neck.
    Head,
}

impl Region {
    /// The label as text and JSON spell it: `torso`, `left_leg`, `right_arm`, ...
    pub fn name(self) -> &'static str {
        match self {
            Region::Torso => "torso",
            Region::LeftLeg => "left_leg",
            Region::RightLeg => "right_leg",
            Region::LeftArm => "left_arm",
            Region::RightArm => "right_arm",
            Region::Head => "head",
        }
    }
}

/// The measurement levels of a body: the heights its chest, waist and hip girths are taken at
/// (found by `shape::measure`, carried in a mannequin file's header).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Levels {
    /// Chest level (mm).
    #[serde(rename = "chest_mm")]
    pub chest: f64,
    /// Waist level (mm).
    #[serde(rename = "waist_mm")]
    pub waist: f64,
    /// Hip level (mm).
    #[serde(rename = "hip_mm")]
    pub hip: f64,
}

/// Landmark heights (mm, canonical frame) and the armholes.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Landmarks {
    /// Body height, the stature: the crown's height above the floor, the frame's z = 0 (a
    /// scan's lowest point when it was loaded; for the pose-symmetric scan, where the fitted
    /// model's soles stand). Not the body's extent: a scanner cuts the soles at the floor,
    /// and a foot lifted sideways keeps more of its sole, which re-posing swings 5-17 mm
    /// below the floor (the demo's customer, MakeHuman bodies with a leg 3-14 degrees out).
    #[serde(rename = "height_mm")]
    pub height: f64,
    /// Where the legs join (to 0.1 mm): just above it the torso is one loop.
    #[serde(rename = "crotch_mm")]
    pub crotch: f64,
    /// The narrowest level of the legs near the floor (the ankles): where the legs end.
    #[serde(rename = "ankle_mm")]
    pub ankle: f64,
    /// The left armpit's height (`left_armhole.armpit`): where the arm's loop joins the
    /// torso's going up or, for an arm resting on the torso, the top of the contact.
    #[serde(rename = "left_armpit_mm")]
    pub left_armpit: f64,
    /// The right armpit's height (`right_armhole.armpit`), as the left's.
    #[serde(rename = "right_armpit_mm")]
    pub right_armpit: f64,
    /// The narrowest torso level between the armpits and the head.
    #[serde(rename = "neck_mm")]
    pub neck: f64,
    /// The torso's centre line: its bounding-box centre (x) just below the armpits.
    #[serde(rename = "centre_x_mm")]
    pub centre_x: f64,
    /// Where the left arm is cut off the torso (the subject's left, +X).
    pub left_armhole: Armhole,
    /// Where the right arm is cut off the torso.
    pub right_armhole: Armhole,
}

impl Landmarks {
    /// The higher of the two armpits: above it, no section holds a separate arm.
    pub fn armpit(&self) -> f64 {
        self.left_armpit.max(self.right_armpit)
    }

    /// Which of the bands between the crotch, the armpits and the neck `z` lies in: the
    /// number of those landmarks at or below it.
    fn band(&self, z: f64) -> usize {
        [self.crotch, self.left_armpit, self.right_armpit, self.neck]
            .iter()
            .filter(|&&h| h <= z)
            .count()
    }
}

/// Why a body could not be segmented.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum RegionError {
    /// No section at mid-torso height.
    #[error(
        "no torso found at {z:.0} mm (60% of the height): is this a standing body in the canonical frame?"
    )]
    NoTorso {
        /// The height looked at.
        z: f64,
    },
    /// The legs never join below the torso.
    #[error(
        "no crotch found: the legs followed up from the shins do not meet below mid-torso \
         (is this one standing person?)"
    )]
    NoCrotch,
    /// Not two legs at the shins.
    #[error(
        "no crotch found: {loops} loop(s) at z = {z:.0} mm (the shins) where two legs should \
         be: scan standing with the feet apart (thighs may touch, shins must not)"
    )]
    NoLegs {
        /// The height looked at.
        z: f64,
        /// The loops found there.
        loops: usize,
    },
    /// No arm joins the torso on one side between mid-torso and the chin.
    #[error(
        "no {side} arm beside the torso from {from:.0} to {to:.0} mm (the chin): hold the arms \
         10-90 degrees out; read a mannequin from the OBJ, PLY or glb file dressform wrote"
    )]
    NoArm {
        /// "left" or "right".
        side: &'static str,
        /// Where the search began (mm): mid-torso.
        from: f64,
        /// Where it ended (mm): the chin.
        to: f64,
    },
    /// No shoulder on one side above the armpit.
    #[error(
        "no {side} shoulder found above the armpit at {armpit:.0} mm: the front silhouette has \
         no edge between the neck and the arm there (is the arm raised above the shoulder?)"
    )]
    NoShoulder {
        /// "left" or "right".
        side: &'static str,
        /// The armpit's height (mm).
        armpit: f64,
    },
}

/// A body's landmarks and how its loops are labelled; labels loops of any section.
#[derive(Debug, Clone)]
pub struct BodyRegions {
    /// The landmarks found (or carried, see [`BodyRegions::armless`]).
    pub landmarks: Landmarks,
    labelling: Labelling,
}

/// How the loops of a section are labelled.
#[derive(Debug, Clone)]
enum Labelling {
    /// By the levels tracked on the body (spaced `step` mm), for a scan.
    Tracked { step: f64, levels: Vec<LabelledSection> },
    /// By the landmarks alone, for a body without arms and head whose landmarks are known (a
    /// mannequin dressform made): below the crotch a leg, by its side of the centre line;
    /// above, the torso.
    Armless,
}

/// One tracked level: its loops and their labels.
#[derive(Debug, Clone)]
struct LabelledSection {
    section: Section,
    labels: Vec<Region>,
}

/// Default spacing of the tracking levels (mm).
pub const TRACKING_STEP_MM: f64 = 5.0;

impl BodyRegions {
    /// The regions of a body without arms and head (a mannequin dressform made, whose
    /// `landmarks` its file carries): the torso above the crotch, the legs below.
    pub fn armless(landmarks: Landmarks) -> BodyRegions {
        BodyRegions { landmarks, labelling: Labelling::Armless }
    }

    /// Segments `body` (canonical frame), tracking loops every `step` mm.
    pub fn find(body: &Mesh, step: f64) -> Result<BodyRegions, RegionError> {
        Self::find_and_cut(body, step, &[]).0
    }

    /// [`Self::find`], and the sections of `body` at `heights`, cut in the same sweep as the
    /// tracking levels (returned whether or not segmentation succeeds).
    pub fn find_and_cut(
        body: &Mesh,
        step: f64,
        heights: &[f64],
    ) -> (Result<BodyRegions, RegionError>, Vec<Section>) {
        let (regions, cut, ()) = Self::find_and_cut_beside(body, step, heights, || ());
        (regions, cut)
    }

    /// [`Self::find_and_cut`], running `beside` alongside the tracking: the sweep keeps every
    /// core busy, while the tracking's level-by-level stretches leave one idle (a caller's own
    /// work on the body, such as its topology check, fills it).
    pub fn find_and_cut_beside<T: Send>(
        body: &Mesh,
        step: f64,
        heights: &[f64],
        beside: impl FnOnce() -> T + Send,
    ) -> (Result<BodyRegions, RegionError>, Vec<Section>, T) {
        let Some(bounds) = body.bounds() else {
            let (cut, t) = rayon::join(|| sections(body, heights), beside);
            return (Err(RegionError::NoTorso { z: 0.0 }), cut, t);
        };
        let (floor, height) = (bounds.min.z, bounds.size().z);
        let n = ((height / step).floor() as usize).max(1);
        let levels: Vec<f64> = (0..n).map(|i| floor + step * (i as f64 + 0.5)).collect();
        let mut cut = sections(body, &[&levels[..], heights].concat());
        let requested = cut.split_off(n);
        let (regions, t) = rayon::join(|| tracking::track(body, step, floor, height, cut), beside);
        (regions, requested, t)
    }

    /// The torso's loop in `section` (cut from the same body; `None` where there is none): the
    /// largest loop labelled torso (at and above the neck, head), clipped to the inner side of
    /// both armholes (above each armpit), so that it holds no arm material (an armless body
    /// has none, and is not clipped).
    pub fn torso_of(&self, section: &Section) -> Option<Contour> {
        let m = &self.landmarks;
        let labels = self.label(section);
        let found = largest_with(section, &labels, Region::Torso)
            .or_else(|| largest_with(section, &labels, Region::Head));
        found.map(|c| match self.labelling {
            Labelling::Tracked { .. } => {
                let c = m.left_armhole.clip(c, section.height);
                m.right_armhole.clip(&c, section.height)
            }
            Labelling::Armless => c.clone(),
        })
    }

    /// Labels for the loops of `section` (cut from the same body at any height): each loop
    /// takes the label of the innermost tracked loop that holds its centroid (or, failing that, the
    /// nearest tracked centroid) at the nearest tracked level between the same landmarks, so
    /// that a cut just below the crotch or an armpit is never labelled from a level above it.
    pub fn label(&self, section: &Section) -> Vec<Region> {
        let z = section.height;
        let m = &self.landmarks;
        let (step, levels) = match &self.labelling {
            Labelling::Tracked { step, levels } => (*step, levels),
            Labelling::Armless => {
                let side = |c: DVec2| side(c.x - m.centre_x, Region::LeftLeg, Region::RightLeg);
                let region =
                    |l: &Contour| if z < m.crotch { side(l.centroid()) } else { Region::Torso };
                return section.loops.iter().map(region).collect();
            }
        };
        let band = m.band(z);
        let level = levels
            .iter()
            .filter(|l| self.landmarks.band(l.section.height) == band)
            .min_by(|a, b| (a.section.height - z).abs().total_cmp(&(b.section.height - z).abs()))
            .unwrap_or_else(|| {
                let i = ((z - levels[0].section.height) / step).round();
                &levels[(i.max(0.0) as usize).min(levels.len() - 1)]
            });
        let tracked = &level.section.loops;
        // A hole (clockwise: thighs touching below the crotch enclose one) is no part of its
        // own, and holds no loop.
        let outlines: Vec<bool> = tracked.iter().map(|l| l.signed_area() > 0.0).collect();
        section
            .loops
            .iter()
            .map(|l| {
                let c = l.centroid();
                // The innermost outline holding it: a hand pressed into the hip or thigh may
                // cross the skin there (a posed mesh's blend skinning does), its loop then
                // lying inside the torso's.
                let inside =
                    (0..tracked.len()).rev().find(|&k| outlines[k] && tracked[k].contains(c));
                let nearest = || {
                    (0..tracked.len()).min_by(|&a, &b| {
                        let da = tracked[a].centroid().distance_squared(c);
                        let db = tracked[b].centroid().distance_squared(c);
                        da.total_cmp(&db)
                    })
                };
                match inside.or_else(nearest) {
                    Some(k) => level.labels[k],
                    None => fallback_region(c, section.height, m),
                }
            })
            .collect()
    }
}

/// The region of a point at height `z` when no tracked loop is near: by landmarks alone.
fn fallback_region(c: DVec2, z: f64, m: &Landmarks) -> Region {
    match () {
        _ if z >= m.neck => Region::Head,
        _ if z >= m.crotch => {
            let p = c.extend(z);
            if m.left_armhole.beyond(p) > 0.0 {
                Region::LeftArm
            } else if m.right_armhole.beyond(p) > 0.0 {
                Region::RightArm
            } else {
                Region::Torso
            }
        }
        _ => side(c.x - m.centre_x, Region::LeftLeg, Region::RightLeg),
    }
}

/// `left` for a point `dx` to the subject's left (+X) of the centre line, else `right`.
fn side(dx: f64, left: Region, right: Region) -> Region {
    if dx >= 0.0 { left } else { right }
}

/// The largest loop of `section` labelled `region` (`labels` as from [`BodyRegions::label`]).
pub fn largest_with<'a>(
    section: &'a Section,
    labels: &[Region],
    region: Region,
) -> Option<&'a Contour> {
    section.loops.iter().zip(labels).find(|&(_, &r)| r == region).map(|(l, _)| l)
}

#[cfg(test)]
mod tests {
    use super::Region;

    #[test]
    fn labels_are_spelled_alike_in_text_and_json() {
        let all = [
            Region::Torso,
            Region::LeftLeg,
            Region::RightLeg,
            Region::LeftArm,
            Region::RightArm,
            Region::Head,
        ];
        for r in all {
            assert_eq!(serde_json::to_string(&r).unwrap(), format!("\"{}\"", r.name()));
        }
    }
}
