//! Shape symmetry of cross-sections (paper section 3.2): each torso section is made symmetric
//! about the body's symmetry line ([`axial`], eq. 5-8), each pair of leg sections is made into
//! mirror images of each other ([`bilateral`], eq. 9-12), and every result is rescaled so that
//! its girth is preserved ([`Preserve`]).
//!
//! Both cast `n` rays from a section's centre ([`rays`]). Ray `i` leaves at the angle
//! `3π/2 + 2π i / n` (measured from +X, counter-clockwise seen from above), so ray 0 points
//! to the front (-Y), ray `n/2` to the back, and the mirror image of ray `i` about the
//! vertical line through the centre is ray `n - i`. `n` must be even.

pub mod axial;
pub mod bilateral;
pub mod rays;

use crate::body::slice::Contour;
use glam::DVec2;
use serde::{Deserialize, Serialize};

/// Which girth the final rescale preserves.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Preserve {
    /// The tape girth (the convex hull's perimeter): what a tailor measures. The default.
    #[default]
    Tape,
    /// The contour's own length: the paper's literal rule.
    Contour,
}

impl Preserve {
    /// Both rules.
    pub const ALL: [Preserve; 2] = [Preserve::Tape, Preserve::Contour];

    /// The rule's name: `tape` or `contour` (as JSON and the command line spell it).
    pub fn name(self) -> &'static str {
        match self {
            Preserve::Tape => "tape",
            Preserve::Contour => "contour",
        }
    }

    /// The girth of `contour` this rule preserves.
    pub fn girth(self, contour: &Contour) -> f64 {
        match self {
            Preserve::Tape => contour.tape_girth(),
            Preserve::Contour => contour.perimeter(),
        }
    }
}

/// Why a section could not be made symmetric.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SymmetryError {
    /// The ray count is unusable.
    #[error("--rays {0}: the number of rays must be even and at least 8")]
    BadRayCount(usize),
    /// A section without area.
    #[error("a section at z = {0:.1} mm has no area to make symmetric")]
    EmptySection(f64),
}

/// Checks a ray count: even, at least 8.
pub fn check_rays(n: usize) -> Result<(), SymmetryError> {
    if n >= 8 && n.is_multiple_of(2) { Ok(()) } else { Err(SymmetryError::BadRayCount(n)) }
}

/// Scales `points` about `centre` so that the girth `preserve` measures becomes `target`
/// (the final step of eq. 8 and eq. 12).
pub fn rescale(points: &mut [DVec2], centre: DVec2, preserve: Preserve, target: f64) {
    let current = preserve.girth(&Contour { points: points.to_vec() });
    if current > 0.0 && target.is_finite() {
        let s = target / current;
        for p in points.iter_mut() {
            *p = centre + (*p - centre) * s;
        }
    }
}
