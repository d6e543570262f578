//! The fidelity report's judgement of each ring: whether the form takes the mannequin's girth
//! there ([`RingStatus`], [`GirthReach`]) and which actuators limit its shape
//! ([`Saturation`]'s wording). The commands print these; the rules live here, next to the fit.

use super::rings::{RingFit, SHAPE_NOTE_MM, Saturation};
use std::fmt;

/// How well one ring takes the mannequin's section.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum RingStatus {
    /// The mannequin has no section where the ring shapes it.
    NoBody,
    /// The form's girth misses the mannequin's by [`SHAPE_NOTE_MM`] or more.
    OutOfReach {
        /// The mannequin's girth minus the form's (mm): positive where the mannequin is
        /// larger than the form's largest size.
        excess_mm: f64,
    },
    /// Girth and shape taken: no actuator saturates.
    Ok,
    /// Girth taken, but some actuator cannot reach its shape target.
    ShapeLimited,
}

/// Where the mannequin's girth at a ring lies against the form's range.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum GirthReach {
    /// Beyond the form's largest size by this much (mm).
    Beyond(f64),
    /// Below the form's smallest size by this much (mm).
    Below(f64),
    /// Within [`SHAPE_NOTE_MM`] of the form's girth.
    Matched,
}

impl RingFit {
    /// The mannequin's girth minus the form's at this ring (mm).
    pub fn excess_girth_mm(&self) -> f64 {
        self.mannequin_girth_mm - self.form_girth_mm
    }

    /// The ring's status in the fidelity report.
    pub fn status(&self) -> RingStatus {
        let excess_mm = self.excess_girth_mm();
        if self.mannequin_girth_mm == 0.0 {
            RingStatus::NoBody
        } else if excess_mm.abs() >= SHAPE_NOTE_MM {
            RingStatus::OutOfReach { excess_mm }
        } else if self.saturated.is_empty() {
            RingStatus::Ok
        } else {
            RingStatus::ShapeLimited
        }
    }

    /// Where the mannequin's girth lies against the form's range at this ring.
    pub fn girth_reach(&self) -> GirthReach {
        let excess = self.excess_girth_mm();
        if excess >= SHAPE_NOTE_MM {
            GirthReach::Beyond(excess)
        } else if excess <= -SHAPE_NOTE_MM {
            GirthReach::Below(-excess)
        } else {
            GirthReach::Matched
        }
    }
}

impl fmt::Display for RingStatus {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            RingStatus::NoBody => write!(f, "no body"),
            RingStatus::OutOfReach { excess_mm } => {
                write!(f, "girth {excess_mm:+.0} mm out of reach")
            }
            RingStatus::Ok => write!(f, "ok"),
            RingStatus::ShapeLimited => write!(f, "shape limited"),
        }
    }
}

impl fmt::Display for GirthReach {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            GirthReach::Beyond(mm) => {
                write!(f, "{mm:.0} mm of girth beyond the form's largest size")
            }
            GirthReach::Below(mm) => {
                write!(f, "{mm:.0} mm of girth below the form's smallest size")
            }
            GirthReach::Matched => write!(f, "girth matched; shape limited"),
        }
    }
}

impl fmt::Display for Saturation {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let side =
            if self.beyond_mm > 0.0 { "beyond its stroke" } else { "inside its retracted end" };
        write!(f, "{} {:.1} mm {side}", self.actuator, self.beyond_mm.abs())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ring(mannequin: f64, form: f64, saturated: &[f64]) -> RingFit {
        RingFit {
            ring: "waist".into(),
            anchor: None,
            form_height_mm: 1080.0,
            mannequin_height_mm: 1060.0,
            offset_mm: 20.0,
            lifted: false,
            mannequin_girth_mm: mannequin,
            form_girth_mm: form,
            rms_radial_gap_mm: 0.0,
            largest_radial_gap_mm: 0.0,
            panel_gaps_mm: Default::default(),
            saturated: (saturated.iter())
                .map(|&beyond_mm| Saturation { actuator: "waist-front".into(), beyond_mm })
                .collect(),
        }
    }

    #[test]
    fn a_ring_is_judged_by_its_girth_first_then_its_shape() {
        assert_eq!(ring(0.0, 700.0, &[]).status(), RingStatus::NoBody);
        let small = ring(650.0, 700.0, &[-12.0]);
        assert_eq!(small.status(), RingStatus::OutOfReach { excess_mm: -50.0 });
        assert_eq!(small.status().to_string(), "girth -50 mm out of reach");
        assert_eq!(small.girth_reach(), GirthReach::Below(50.0));
        assert_eq!(ring(800.5, 800.0, &[]).status(), RingStatus::Ok);
        let limited = ring(800.5, 800.0, &[4.3]);
        assert_eq!(limited.status(), RingStatus::ShapeLimited);
        assert_eq!(limited.girth_reach(), GirthReach::Matched);
        assert_eq!(limited.saturated[0].to_string(), "waist-front 4.3 mm beyond its stroke");
        let large = ring(900.0, 880.0, &[20.0]);
        assert_eq!(
            large.girth_reach().to_string(),
            "20 mm of girth beyond the form's largest size"
        );
    }
}
