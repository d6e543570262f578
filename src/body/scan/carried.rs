//! What a body file written by dressform carries in its header, so that dressform reads its
//! own mannequin back as a body: how the file's coordinates map to the canonical frame (the
//! floor included), the landmarks and the measurement levels, as one line
//! `dressform: {json}` (an OBJ `#` line, a PLY `comment`, a glb asset's `extras`; STL has no
//! header, so an STL mannequin is read as any scan is, and fails to segment).
//!
//! Carried rather than found again: a mannequin has no arms, head or feet, so neither its
//! floor (its lowest point is the ankle cap) nor its levels (the chest is found just below the
//! armpits, which it no longer has) can be found on it; the header keeps them exactly, and
//! `measure`, `slice` and `info` then give the mannequin's own girths at the scan's heights.

use crate::body::regions::{Landmarks, Levels};
use crate::body::scan::format::comment_value;
use crate::body::scan::frame::FileFrame;
use serde::{Deserialize, Serialize};

/// The key of the header line (`dressform: {json}`).
pub const HEADER_KEY: &str = "dressform";

/// A body as a file written by dressform describes it (see the module documentation).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct CarriedBody {
    /// How the file's coordinates map to the canonical frame.
    pub frame: FileFrame,
    /// The body's landmarks (canonical frame, mm).
    pub landmarks: Landmarks,
    /// The levels its chest, waist and hip are measured at.
    pub levels: Levels,
}

impl CarriedBody {
    /// The header line: `dressform: ` and the body as one line of JSON.
    pub fn header_line(&self) -> String {
        let json = serde_json::to_string(self).expect("numbers and plain structs serialise");
        format!("{HEADER_KEY}: {json}")
    }

    /// The body the header `comments` describe, if they have a `dressform:` line; an error
    /// names what is wrong with the line.
    pub fn from_comments(comments: &[String]) -> Result<Option<CarriedBody>, String> {
        let Some(json) = comment_value(comments, HEADER_KEY) else { return Ok(None) };
        let wrong = |e: String| format!("header line '{HEADER_KEY}:': {e}");
        let body: CarriedBody = serde_json::from_str(json).map_err(|e| wrong(e.to_string()))?;
        body.check().map_err(wrong)?;
        Ok(Some(body))
    }

    /// Checks that the landmarks and levels lie in their order from the ankle up.
    fn check(&self) -> Result<(), String> {
        let m = &self.landmarks;
        let l = &self.levels;
        let (low_armpit, high_armpit) =
            (m.left_armpit.min(m.right_armpit), m.left_armpit.max(m.right_armpit));
        let landmarks = [0.0, m.ankle, m.crotch, low_armpit, high_armpit, m.neck, m.height];
        if !landmarks.windows(2).all(|w| w[0] <= w[1]) || m.ankle >= m.crotch {
            return Err(
                "landmarks: not in order (0 <= ankle < crotch <= armpits <= neck <= height)".into(),
            );
        }
        if [l.hip, l.waist, l.chest].iter().any(|&z| z <= m.crotch || z >= m.neck) {
            return Err("levels: the chest, waist and hip must lie between crotch and neck".into());
        }
        Ok(())
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::body::regions::Armhole;
    use glam::DVec3;

    /// A mannequin's header as tests need one.
    pub(crate) fn body() -> CarriedBody {
        let armhole = |side: f64| {
            Armhole::through(
                DVec3::new(side * 150.0, 0.0, 1250.0),
                DVec3::new(side * 190.0, 0.0, 1400.0),
                DVec3::Y,
                side,
            )
        };
        CarriedBody {
            frame: FileFrame {
                units: crate::body::scan::frame::Units::Cm,
                rotation: [[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]],
                translation: [0.0; 3],
            },
            landmarks: Landmarks {
                height: 1700.0,
                crotch: 800.0,
                ankle: 90.0,
                left_armpit: 1250.0,
                right_armpit: 1250.0,
                neck: 1450.0,
                centre_x: 0.0,
                left_armhole: armhole(1.0),
                right_armhole: armhole(-1.0),
            },
            levels: Levels { chest: 1230.0, waist: 1050.0, hip: 900.0 },
        }
    }

    #[test]
    fn the_header_line_reads_back_exactly() {
        let line = body().header_line();
        assert!(line.starts_with("dressform: {") && !line.contains('\n'), "{line}");
        let comments = vec!["units: cm".to_string(), line];
        assert_eq!(CarriedBody::from_comments(&comments), Ok(Some(body())));
        assert_eq!(CarriedBody::from_comments(&comments[..1]), Ok(None));
    }

    #[test]
    fn a_broken_or_impossible_header_is_named() {
        let broken = vec!["dressform: {\"frame\": 3}".to_string()];
        let e = CarriedBody::from_comments(&broken).unwrap_err();
        assert!(e.starts_with("header line 'dressform:': "), "{e}");
        let mut upside_down = body();
        upside_down.landmarks.crotch = 1500.0;
        let e = CarriedBody::from_comments(&[upside_down.header_line()]).unwrap_err();
        assert!(e.contains("landmarks: not in order"), "{e}");
        let mut low_chest = body();
        low_chest.levels.chest = 700.0;
        let e = CarriedBody::from_comments(&[low_chest.header_line()]).unwrap_err();
        assert!(e.contains("levels:"), "{e}");
    }
}
