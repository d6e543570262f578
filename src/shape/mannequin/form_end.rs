//! Where the form ends: a dress form with legs down to the ankles, or one that ends at the
//! thigh.
//!
//! With [`StopAt::Thigh`] the legs end at mid-thigh (ISO 8559-1's mid-thigh girth: midway
//! between the crotch and the knee), closed by a flat cap each: the leg layers below are
//! dropped, those kept are the full-length legs' own (same heights, shapes and girths), so the
//! thighs a form's thigh rings shape are the same either way. The knee is not a landmark; it
//! is placed at [`KNEE_SHARE`] of the body's height.

use super::Layer;
use crate::body::regions::Landmarks;

/// Where the form ends below the crotch.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StopAt {
    /// At mid-thigh: the legs end halfway from the crotch to the knee.
    Thigh,
}

impl StopAt {
    /// Every place to stop.
    pub const ALL: [StopAt; 1] = [StopAt::Thigh];

    /// The place's name: `thigh` (as the command line spells it).
    pub fn name(self) -> &'static str {
        match self {
            StopAt::Thigh => "thigh",
        }
    }

    /// The height (mm) the legs reach down to on a body with the landmarks `m`.
    pub fn height(self, m: &Landmarks) -> f64 {
        match self {
            StopAt::Thigh => 0.5 * (m.crotch + KNEE_SHARE * m.height),
        }
    }
}

/// The knee joint's height as a share of the body's height (Winter, *Biomechanics and Motor
/// Control of Human Movement*, 4th ed., Fig. 4.1: 0.285 H). On the demo's customer (1700 mm,
/// crotch at 789-794) mid-thigh falls about 155 mm below the crotch; the reference form's
/// thigh rings shape it 102 mm below.
const KNEE_SHARE: f64 = 0.285;

/// The number of a leg's rings (bottom to top; `is_layer` flags its layers) to drop so that
/// it ends at `z`: every ring below the highest layer at or below `z` (none when no layer is
/// that low).
pub(super) fn dropped_below(leg: &[Layer], is_layer: &[bool], z: f64) -> usize {
    leg.iter().zip(is_layer).rposition(|(ring, layer)| *layer && ring.z <= z).unwrap_or(0)
}
