//! The host's one rule about targets: **nothing outside an actuator's stroke reaches the
//! wire.**
//!
//! A target is a [`SafeTarget`], which can only be built against a stroke, by
//! [`SafeTarget::within`] (refusing anything outside `[0, stroke]`) or [`SafeTarget::clamped`]
//! (clamping into it). The move planner turns set-points into `SafeTarget`s and builds its
//! `Targets` / `AllTargets` packets from them alone, so a set-point file, a retry or a resumed
//! move cannot put another position on the bus. The strokes are the form description's,
//! which the session has checked against every node's reported capabilities.

use firmware_protocol::{HUNDREDTHS_PER_MM, Position};

/// A target position proven to lie within an actuator's stroke.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct SafeTarget(Position);

impl SafeTarget {
    /// `mm` rounded to 0.01 mm, if it lies in `[0, stroke]`; `None` otherwise (or if it is
    /// not a number).
    pub fn within(mm: f64, stroke: Position) -> Option<Self> {
        if !(0.0..=stroke.mm()).contains(&mm) {
            return None;
        }
        let hundredths = (mm * HUNDREDTHS_PER_MM).round();
        // Rounding cannot leave the stroke: the stroke is a whole number of hundredths.
        let raw = (hundredths as u16).min(stroke.hundredths_mm());
        Position::new(raw).map(Self)
    }

    /// `mm` clamped into `[0, stroke]` (NaN becomes 0, the home end).
    pub fn clamped(mm: f64, stroke: Position) -> Self {
        let top = f64::from(stroke.hundredths_mm());
        let hundredths =
            if mm.is_nan() { 0.0 } else { (mm * HUNDREDTHS_PER_MM).round().clamp(0.0, top) };
        // `hundredths` is within the stroke, itself a valid position.
        Self(Position::new(hundredths as u16).unwrap_or(Position::ZERO))
    }

    /// The wire position.
    pub fn position(self) -> Position {
        self.0
    }

    /// The target in mm.
    pub fn mm(self) -> f64 {
        self.0.mm()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn targets_stay_within_the_stroke() {
        let stroke = Position::new(6000).unwrap();
        assert_eq!(SafeTarget::within(23.456, stroke).unwrap().position().hundredths_mm(), 2346);
        assert_eq!(SafeTarget::within(60.0, stroke).unwrap().mm(), 60.0);
        assert!(SafeTarget::within(60.004, stroke).is_none());
        assert!(SafeTarget::within(-0.001, stroke).is_none());
        assert!(SafeTarget::within(f64::NAN, stroke).is_none());
        assert_eq!(SafeTarget::clamped(75.0, stroke).mm(), 60.0);
        assert_eq!(SafeTarget::clamped(-3.0, stroke).mm(), 0.0);
        assert_eq!(SafeTarget::clamped(f64::INFINITY, stroke).mm(), 60.0);
        assert_eq!(SafeTarget::clamped(f64::NAN, stroke).mm(), 0.0);
    }
}
