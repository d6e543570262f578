//! The symmetric mannequin: torso and legs cut into layers, each layer made symmetric
//! ([`crate::shape::symmetry`]), and the layers rebuilt into one watertight mesh ([`rebuild`]).
//!
//! Layers (defaults from the paper): 100 torso layers from just above the crotch to the neck,
//! 50 leg layers from the ankles to just below the crotch, faired across heights against the
//! scanner's leftover noise, girths kept ([`fairing`]). Above the armpits the torso sections
//! are cut at the armholes ([`crate::body::regions::Armhole`]), so the arms are not part of the
//! torso: the cut edges stack into flat arm plates, each rimmed by one smooth curve
//! ([`arm_plates`]). Near the armpits each side's half of a torso layer is taken at the height
//! aligned by that side's own armpit ([`side_heights`]), so armpits at different heights put
//! no underarm under the plates. Every torso layer is horizontal and keeps
//! its section's girth; above the arm plates the mesh is built from rings bent up over the
//! shoulders, which follow the shoulder top with its own slope ([`shoulder_cap`]). Within
//! 100 mm below the crotch the legs' mesh has rings between their layers, finer towards the
//! crotch ([`layers`]; mesh only, as the shoulder cap's). The legs' top rings are eased into
//! the hips above them ([`thighs`]), so the crotch join has no step. Below it the legs stand
//! straight and parallel, as a dress form's hang, or as the customer stood ([`leg_stance`]),
//! and reach the ankles or end at the thigh ([`form_end`]).
//! All layers share one symmetry plane, x = `axis`: the median of the torso sections'
//! bounding-box centres.

mod arm_plates;
mod fairing;
mod form_end;
mod layers;
mod leg_stance;
mod rebuild;
mod shoulder_cap;
mod shoulder_slope;
mod side_heights;
mod thighs;

use crate::body::mesh::Mesh;
use crate::body::regions::{Armhole, Landmarks, Region, RegionError};
use crate::body::segmented_body::SegmentedBody;
use crate::shape::symmetry::{Preserve, SymmetryError};
use glam::{DVec2, DVec3};
use rebuild::TorsoRing;
use serde::Serialize;

pub use form_end::StopAt;
pub use leg_stance::LegStance;

/// How the mannequin is built.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MannequinOptions {
    /// Torso layers (paper: 100).
    pub torso_layers: usize,
    /// Leg layers (paper: 50).
    pub leg_layers: usize,
    /// Rays per section (paper: 360); even.
    pub rays: usize,
    /// The girth each layer keeps.
    pub preserve: Preserve,
    /// How the legs stand ([`leg_stance`]).
    pub legs: LegStance,
    /// Where the legs end: at the ankles (`None`) or higher ([`form_end`]).
    pub stop_at: Option<StopAt>,
}

impl Default for MannequinOptions {
    fn default() -> Self {
        MannequinOptions {
            torso_layers: 100,
            leg_layers: 50,
            rays: 360,
            preserve: Preserve::Tape,
            legs: LegStance::default(),
            stop_at: None,
        }
    }
}

/// One symmetric layer: a horizontal ring of the mannequin.
#[derive(Debug, Clone, Serialize)]
pub struct Layer {
    /// Torso, left leg or right leg.
    pub region: Region,
    /// Height (mm, canonical frame).
    pub z: f64,
    /// The ray origin of the layer.
    pub centre: [f64; 2],
    /// The ring, counter-clockwise from above, starting at the front (see [`crate::shape::symmetry`]).
    #[serde(serialize_with = "serialize_points")]
    pub points: Vec<DVec2>,
    /// The input section's tape girth (mm): the body's torso section at the layer's height,
    /// whose girth the layer keeps (eq. 8). Near the armpits the layer's shape comes from each
    /// side's section at another height ([`side_heights`]); its girth is still this one's.
    pub input_tape_girth: f64,
    /// The input section's contour length (mm).
    pub input_contour_length: f64,
    /// The ring's tape girth (mm).
    pub tape_girth: f64,
    /// The ring's contour length (mm).
    pub contour_length: f64,
}

fn serialize_points<S: serde::Serializer>(points: &[DVec2], s: S) -> Result<S::Ok, S::Error> {
    s.collect_seq(points.iter().map(|p| [p.x, p.y]))
}

/// The symmetric mannequin.
#[derive(Debug, Clone)]
pub struct Mannequin {
    /// The symmetry plane x = `axis` (mm).
    pub axis: f64,
    /// The landmarks of the input body.
    pub landmarks: Landmarks,
    /// The options used.
    pub options: MannequinOptions,
    /// Torso layers, bottom to top.
    pub torso: Vec<Layer>,
    /// Left-leg layers, bottom to top.
    pub left_leg: Vec<Layer>,
    /// Right-leg layers, bottom to top.
    pub right_leg: Vec<Layer>,
    /// The height from which the mesh's torso rings bend up over the shoulders (see
    /// [`shoulder_cap`]); below it they are the torso layers.
    pub shoulder_cap_from: f64,
    /// The watertight, consistently oriented mannequin mesh.
    pub mesh: Mesh,
}

impl Mannequin {
    /// The mannequin's own landmarks: the input body's, made symmetric about the plane
    /// x = `axis` as the mannequin is — each armhole the mean of its own and the other one
    /// mirrored, both armpits at their mean height, the centre line on the plane. Its file
    /// carries them ([`crate::body::scan::carried`]).
    pub fn own_landmarks(&self) -> Landmarks {
        symmetric_landmarks(&self.landmarks, self.axis)
    }
}

/// The smooth step from 0 (at `s` <= 0) to 1 (at `s` >= 1), with zero slope at both ends:
/// how the rebuild's easings (arm plates, shoulder cap, thighs) fade in and out.
fn smoothstep(s: f64) -> f64 {
    let s = s.clamp(0.0, 1.0);
    s * s * (3.0 - 2.0 * s)
}

/// The landmarks `m` made symmetric about the plane x = `axis` (see
/// [`Mannequin::own_landmarks`]).
fn symmetric_landmarks(m: &Landmarks, axis: f64) -> Landmarks {
    let mirror = |p: DVec3| DVec3::new(2.0 * axis - p.x, p.y, p.z);
    let flip = |n: DVec3| DVec3::new(-n.x, n.y, n.z);
    let (l, r) = (&m.left_armhole, &m.right_armhole);
    let left = Armhole {
        armpit: 0.5 * (l.armpit + mirror(r.armpit)),
        shoulder_point: 0.5 * (l.shoulder_point + mirror(r.shoulder_point)),
        normal: (l.normal + flip(r.normal)).normalize_or(l.normal),
        contact: None,
    };
    let right = Armhole {
        armpit: mirror(left.armpit),
        shoulder_point: mirror(left.shoulder_point),
        normal: flip(left.normal),
        contact: None,
    };
    Landmarks {
        left_armpit: left.armpit.z,
        right_armpit: left.armpit.z,
        centre_x: axis,
        left_armhole: left,
        right_armhole: right,
        ..*m
    }
}

/// Why a mannequin could not be built.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum MannequinError {
    /// Segmentation failed.
    #[error(transparent)]
    Regions(#[from] RegionError),
    /// A section could not be made symmetric.
    #[error(transparent)]
    Symmetry(#[from] SymmetryError),
    /// Too few layers.
    #[error("at least 2 torso layers and 2 leg layers are needed (asked {torso} and {legs})")]
    TooFewLayers {
        /// Torso layers asked.
        torso: usize,
        /// Leg layers asked.
        legs: usize,
    },
    /// A layer lacks the loop it needs.
    #[error("no {region:?} loop at z = {z:.1} mm")]
    MissingLoop {
        /// The region looked for.
        region: Region,
        /// The height.
        z: f64,
    },
}

/// Builds the symmetric mannequin of the segmented `body` (canonical frame), with a torso layer exactly at each of the `keep` heights (the chest, waist and hip levels, so that
/// the mannequin keeps exactly the girths a tailor measures).
pub fn build(
    body: &SegmentedBody,
    keep: &[f64],
    options: &MannequinOptions,
) -> Result<Mannequin, MannequinError> {
    if options.torso_layers < 2 || options.leg_layers < 2 {
        return Err(MannequinError::TooFewLayers {
            torso: options.torso_layers,
            legs: options.leg_layers,
        });
    }
    crate::shape::symmetry::check_rays(options.rays)?;
    let layers::SymmetricLayers { axis, mut torso, mut left_leg, mut right_leg, mut is_layer } =
        layers::symmetric_layers(body, keep, options)?;
    let landmarks = *body.landmarks();
    let own = symmetric_landmarks(&landmarks, axis);
    let plates = [&own.left_armhole, &own.right_armhole];
    let heights: Vec<f64> = torso.iter().map(|layer| layer.z).collect();
    let on_plates = |k: usize, p| fairing::on_plates(&plates, p, heights[k]);
    fairing::fair(&mut torso, &on_plates, options.preserve, true);
    for leg in [&mut left_leg, &mut right_leg] {
        fairing::fair(leg, &|_, _| false, options.preserve, false);
    }
    let cap = shoulder_cap::build(body.mesh(), &landmarks, &torso, axis, options)?;
    thighs::ease(&torso[0], &torso[1], &mut left_leg, &mut right_leg);
    if options.legs == LegStance::Straight {
        for leg in [&mut left_leg, &mut right_leg] {
            leg_stance::straighten(leg, &is_layer, axis);
        }
    }
    if let Some(stop) = options.stop_at {
        let dropped = form_end::dropped_below(&left_leg, &is_layer, stop.height(&landmarks));
        for rings in [&mut left_leg, &mut right_leg] {
            rings.drain(..dropped);
        }
        is_layer.drain(..dropped);
    }
    let below_cap = torso.iter().take_while(|layer| layer.z < cap.from).count();
    let mut rings = arm_plates::rims(&torso[..below_cap], axis, plates, options.preserve);
    rings.extend(cap.rings.iter().map(|ring| TorsoRing::from_rays(ring)));
    let mut mesh =
        rebuild::rebuild(&rings, cap.neck_centre, &left_leg, &right_leg, axis, landmarks.crotch);
    let on_plate = |p: DVec3| fairing::on_plates(&plates, p.truncate(), p.z);
    shoulder_slope::steepen(&mut mesh, axis, cap.from, &on_plate);
    // The legs' layers without the mesh's rings between them.
    let layers_only = |rings: Vec<Layer>| -> Vec<Layer> {
        rings
            .into_iter()
            .zip(&is_layer)
            .filter(|(_, layer)| **layer)
            .map(|(ring, _)| ring)
            .collect()
    };
    let (left_leg, right_leg) = (layers_only(left_leg), layers_only(right_leg));
    Ok(Mannequin {
        axis,
        landmarks,
        options: *options,
        torso,
        left_leg,
        right_leg,
        shoulder_cap_from: cap.from,
        mesh,
    })
}
