//! Where each side's half of a torso layer is taken from: near the armpits, at the height
//! aligned by that side's own armpit.
//!
//! The mannequin's two armpits lie at the mean of the body's ([`super::symmetric_landmarks`]).
//! A body whose armpits are at different heights (a posed body: the demo customer's, re-posed,
//! are 14.5 mm apart) has, between them, sections cut at the armhole on one side only: there
//! the section holds that side's underarm out to its armhole, the other side is still below its
//! armpit. Eq. 7 averaged the two, so on the mannequin both sides of those layers stood out
//! half the underarm's width (6 mm on the demo) under the arm plates: a flat-faced tab.
//!
//! So a torso layer at height `z` takes its left half (eq. 6) from the body's section at
//! `z + shift` and its right half from `z - shift` ([`SideHeights::at`]), `shift` being half
//! the left armpit's height above the right's: in full from the lower armpit up to the higher
//! one, easing to none [`EASE_MM`] below the lower and above the higher. Each side's underarm
//! then lies at the same height relative to its armpit when eq. 7 averages them, and both
//! reach the mannequin's plates at its own armpits. The layer keeps the girth of the body's
//! section at its own height (eq. 8), as every layer does, so the measurement levels keep
//! their girths exactly.

use super::smoothstep;
use crate::body::regions::Landmarks;

/// Over this height (mm) below the lower armpit and above the higher one the shift eases out:
/// about seven torso layers at the paper's 100 (6.6-7.3 mm apart), so the sampled heights
/// stretch by at most 1.5 x shift / `EASE_MM` (0.22 for the demo's re-posed customer's
/// 7.3 mm), and outside the armpits' band no layer's halves come from sections far apart.
const EASE_MM: f64 = 50.0;

/// The heights each side's half of a torso layer is taken from.
#[derive(Debug, Clone, Copy)]
pub(super) struct SideHeights {
    /// Half the left armpit's height above the right's (mm; negative where it is lower).
    shift: f64,
    /// The lower armpit's height (mm).
    low: f64,
    /// The higher armpit's height (mm).
    high: f64,
}

impl SideHeights {
    /// The heights of the body whose landmarks are `m`.
    pub fn of(m: &Landmarks) -> SideHeights {
        SideHeights {
            shift: 0.5 * (m.left_armpit - m.right_armpit),
            low: m.left_armpit.min(m.right_armpit),
            high: m.left_armpit.max(m.right_armpit),
        }
    }

    /// The heights `[left, right]` from which the left and right halves of the torso layer
    /// at `z` are taken (both `z` exactly where the shift is none).
    pub fn at(&self, z: f64) -> [f64; 2] {
        let rise = smoothstep((z - (self.low - EASE_MM)) / EASE_MM);
        let fall = smoothstep(((self.high + EASE_MM) - z) / EASE_MM);
        let shift = self.shift * rise * fall;
        [z + shift, z - shift]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_side_is_aligned_by_its_own_armpit_between_them_and_eased_out_beyond() {
        // The left armpit at 1275, the right at 1261: the mannequin's at 1268.
        let sides = SideHeights { shift: 7.0, low: 1261.0, high: 1275.0 };
        assert_eq!(sides.at(1268.0), [1275.0, 1261.0], "the mannequin's armpit: each side's");
        for z in [1261.0, 1265.0, 1275.0] {
            assert_eq!(sides.at(z), [z + 7.0, z - 7.0]);
        }
        for z in [1000.0, 1261.0 - EASE_MM, 1275.0 + EASE_MM, 1500.0] {
            assert_eq!(sides.at(z), [z, z], "no shift at {z}");
        }
        // Easing: the sampled heights rise steadily with the layer's.
        let zs: Vec<f64> = (0..400).map(|k| 1150.0 + k as f64).collect();
        for pair in zs.windows(2) {
            let (a, b) = (sides.at(pair[0]), sides.at(pair[1]));
            assert!(b[0] > a[0] && b[1] > a[1], "{a:?} then {b:?}");
        }
    }
}
