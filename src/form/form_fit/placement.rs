//! Where each ring of the form meets the mannequin (see the placement rule in the module
//! above).

use crate::shape::profiles::Profiles;
use form_description::{Anchor, FormDescription};

/// The mannequin's height for a ring's anchor (the form description states which ring has
/// which).
fn level(anchor: Anchor, p: &Profiles) -> f64 {
    match anchor {
        Anchor::Neck => p.landmarks.neck,
        Anchor::Chest => p.levels.chest,
        Anchor::Waist => p.levels.waist,
        Anchor::Hip => p.levels.hip,
    }
}

/// The map from form heights to mannequin heights: piecewise linear through the anchors.
#[derive(Debug, Clone)]
pub struct HeightMap {
    /// (form height, mannequin height), by form height.
    pairs: Vec<(f64, f64)>,
}

impl HeightMap {
    /// The placement of `form`'s rings on the mannequin of `profiles`.
    pub fn new(profiles: &Profiles, form: &FormDescription) -> Self {
        let mut pairs: Vec<(f64, f64)> = form
            .rings
            .iter()
            .filter_map(|r| r.anchor.map(|a| (r.height_mm, level(a, profiles))))
            .collect();
        pairs.sort_by(|a, b| a.0.total_cmp(&b.0));
        pairs.dedup_by(|a, b| a.0 == b.0);
        HeightMap { pairs }
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
