//! Where each ring of the form meets the mannequin: the body level each ring stands for (see
//! the placement rule in the module above).

use crate::body::regions::Region;
use crate::body::slice::Contour;
use crate::shape::measure::{THIGH_BELOW_CROTCH, underbust_band, underbust_fold};
use crate::shape::profiles::Profiles;
use form_description::{Anchor, FormDescription};
use glam::DVec2;
use std::collections::BTreeMap;

/// Where the shoulders level lies between the armpits (0) and the neck (1): two thirds of the
/// way up. Before the form had lifts its shoulder ring shaped the level 0.7 of the way from
/// the chest level to the neck (its built heights through the anchors): 1395 mm on the demo's
/// customer, 1401 by this rule, so the ring keeps the section its panels were sized for.
pub const SHOULDERS_ABOVE_ARMPITS: f64 = 2.0 / 3.0;

/// Where the under-bust level lies between the chest (0) and the waist (1) on a body without
/// a fold under the bust (the measurements' rule, [`underbust_fold`], finds none on a flat
/// front): 0.4 of the way down, where the reference form's under-bust ring was built between
/// its chest and waist rings (80 of 200 mm).
pub const UNDER_BUST_BELOW_CHEST: f64 = 0.4;

/// The mannequin's height for a ring's anchor (the form description states which ring has
/// which). Leg levels are the same on both legs.
pub fn level(anchor: Anchor, p: &Profiles) -> f64 {
    let m = &p.landmarks;
    let armpits = 0.5 * (m.left_armpit + m.right_armpit);
    match anchor {
        Anchor::Neck => m.neck,
        Anchor::Shoulders => armpits + SHOULDERS_ABOVE_ARMPITS * (m.neck - armpits),
        Anchor::Chest => p.levels.chest,
        Anchor::UnderBust => underbust_level(p),
        Anchor::Waist => p.levels.waist,
        Anchor::Abdomen => 0.5 * (p.levels.waist + p.levels.hip),
        Anchor::Hip => p.levels.hip,
        Anchor::Thigh => m.crotch - THIGH_BELOW_CROTCH * m.height,
    }
}

/// The underbust's level on the mannequin: the fold under the bust by the measurements' rule
/// ([`underbust_fold`]) over the torso's layers in its band, else [`UNDER_BUST_BELOW_CHEST`]
/// of the way from the chest to the waist.
fn underbust_level(p: &Profiles) -> f64 {
    let (lo, hi) = underbust_band(&p.levels, p.landmarks.height);
    let profile: Vec<(f64, Contour)> = p
        .layers
        .iter()
        .filter(|l| l.region == Region::Torso && (lo..=hi).contains(&l.z))
        .map(|l| {
            (l.z, Contour { points: l.points.iter().map(|&q| DVec2::from_array(q)).collect() })
        })
        .collect();
    let (chest, waist) = (p.levels.chest, p.levels.waist);
    underbust_fold(&profile)
        .map_or(chest + UNDER_BUST_BELOW_CHEST * (waist - chest), |k| profile[k].0)
}

/// The body level each ring of a form stands for: an anchored ring's level, and for every
/// other ring its built height mapped piecewise-linearly through the anchored torso rings'
/// (built height with the lifts retracted → level; beyond the end ones with the nearest
/// segment's scale, by a plain shift with one anchor, unchanged with none).
#[derive(Debug, Clone)]
pub struct RingLevels {
    /// Ring name → level (mm).
    by_ring: BTreeMap<String, f64>,
}

impl RingLevels {
    /// The levels of `form`'s rings on the mannequin of `profiles`.
    pub fn new(profiles: &Profiles, form: &FormDescription) -> Self {
        // Each anchored ring's level, found once (the under-bust's looks through the layers).
        let anchored: Vec<Option<f64>> =
            form.rings.iter().map(|r| r.anchor.map(|a| level(a, profiles))).collect();
        let mut pairs: Vec<(f64, f64)> = (form.rings.iter().zip(&anchored))
            .filter(|(r, _)| r.anchor.is_some_and(|a| !a.is_leg()))
            .filter_map(|(r, z)| Some((r.height_mm, (*z)?)))
            .collect();
        pairs.sort_by(|a, b| a.0.total_cmp(&b.0));
        pairs.dedup_by(|a, b| a.0 == b.0);
        let by_ring = (form.rings.iter().zip(anchored))
            .map(|(r, z)| (r.name.clone(), z.unwrap_or_else(|| interpolate(&pairs, r.height_mm))))
            .collect();
        RingLevels { by_ring }
    }

    /// The level of the ring named `ring` (NaN for a ring not of the form).
    pub fn of(&self, ring: &str) -> f64 {
        self.by_ring.get(ring).copied().unwrap_or(f64::NAN)
    }
}

/// `form_height` mapped through `pairs` (form height, level), sorted by form height.
fn interpolate(pairs: &[(f64, f64)], form_height: f64) -> f64 {
    match pairs {
        [] => form_height,
        [(f, m)] => form_height - f + m,
        pairs => {
            let k = pairs.partition_point(|p| p.0 < form_height).clamp(1, pairs.len() - 1);
            let ((f0, m0), (f1, m1)) = (pairs[k - 1], pairs[k]);
            m0 + (form_height - f0) * (m1 - m0) / (f1 - f0)
        }
    }
}
