//! Where each ring of the form meets the mannequin (see the placement rule in the module
//! above).

use crate::profiles::Profiles;
use serde::Serialize;
use sim::form::FormDescription;

/// A ring anchored to a mannequin level.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Anchor {
    /// The neck landmark.
    Neck,
    /// The chest level.
    Chest,
    /// The waist level.
    Waist,
    /// The hip level.
    Hip,
}

impl Anchor {
    /// The anchor of a ring of this name, if any.
    pub fn of_ring(name: &str) -> Option<Anchor> {
        match name {
            "neck" => Some(Anchor::Neck),
            "chest" => Some(Anchor::Chest),
            "waist" => Some(Anchor::Waist),
            "hip" => Some(Anchor::Hip),
            _ => None,
        }
    }

    /// The mannequin's height for this anchor.
    fn level(self, p: &Profiles) -> f64 {
        match self {
            Anchor::Neck => p.landmarks.neck,
            Anchor::Chest => p.levels.chest,
            Anchor::Waist => p.levels.waist,
            Anchor::Hip => p.levels.hip,
        }
    }
}

/// The map from form heights to mannequin heights: piecewise linear through the anchors.
#[derive(Debug, Clone)]
pub struct Placement {
    /// (form height, mannequin height), by form height.
    pairs: Vec<(f64, f64)>,
}

impl Placement {
    /// The placement of `form`'s rings on the mannequin of `profiles`.
    pub fn new(profiles: &Profiles, form: &FormDescription) -> Self {
        let mut pairs: Vec<(f64, f64)> = form
            .rings
            .iter()
            .filter_map(|r| Anchor::of_ring(&r.name).map(|a| (r.height_mm, a.level(profiles))))
            .collect();
        pairs.sort_by(|a, b| a.0.total_cmp(&b.0));
        pairs.dedup_by(|a, b| a.0 == b.0);
        Placement { pairs }
    }

    /// The mannequin height that a ring built at `form_height` shapes.
    pub fn mannequin_height(&self, form_height: f64) -> f64 {
        match self.pairs.as_slice() {
            [] => form_height,
            [(f, m)] => form_height - f + m,
            pairs => {
                let k = pairs.partition_point(|p| p.0 < form_height).clamp(1, pairs.len() - 1);
                let ((f0, m0), (f1, m1)) = (pairs[k - 1], pairs[k]);
                m0 + (form_height - f0) * (m1 - m0) / (f1 - f0)
            }
        }
    }
}
