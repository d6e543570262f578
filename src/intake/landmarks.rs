//! A scanner's landmark file beside a scan: same stem, extension `.txt` (`alice.ply`,
//! `alice.txt`), one landmark a line as the SHARP challenge writes them: `name x y z` in the
//! scan's own units and axes, `nan nan nan` for a landmark the scanner did not find. Blank
//! lines and lines starting with `#` are skipped.
//!
//! The pipeline has no landmark input yet (the body model is fitted without landmarks):
//! the landmarks are checked and carried into the outputs (`landmarks.json`, in the scan's
//! coordinates and in the canonical frame), ready for a fit that uses them.

use crate::body::scan::frame::CanonicalFrame;
use crate::messages;
use glam::DVec3;
use serde::Serialize;
use std::path::{Path, PathBuf};

/// The extension of a landmark file.
pub const EXTENSION: &str = "txt";

/// One landmark.
#[derive(Debug, Clone, PartialEq)]
pub struct Landmark {
    /// Its name, as the scanner wrote it.
    pub name: String,
    /// Where it is, in the scan's coordinates; `None` where the scanner did not find it.
    pub position: Option<DVec3>,
}

/// The landmark file beside `scan`, if there is one.
pub fn beside(scan: &Path) -> Option<PathBuf> {
    let path = scan.with_extension(EXTENSION);
    path.is_file().then_some(path)
}

/// Parses the text of a landmark file; `path` names it in errors (one line: the file, the
/// line number and the problem).
pub fn parse(text: &str, path: &Path) -> Result<Vec<Landmark>, String> {
    let mut landmarks: Vec<Landmark> = Vec::new();
    for (n, line) in text.lines().enumerate() {
        let line = line.trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        let at = |what: String| format!("{} line {}: {what}", messages::path(path), n + 1);
        let fields: Vec<&str> = line.split_whitespace().collect();
        let [name, x, y, z] = fields[..] else {
            return Err(at(format!(
                "expected 'name x y z', found {} fields: '{}'",
                fields.len(),
                messages::bounded(&line.escape_default().to_string())
            )));
        };
        let coordinate = |s: &str| match s.parse::<f64>() {
            Ok(v) if v.is_finite() || v.is_nan() => Ok(v),
            _ => Err(at(format!(
                "'{}' is not a coordinate (a number, or nan)",
                messages::bounded(s)
            ))),
        };
        let p = DVec3::new(coordinate(x)?, coordinate(y)?, coordinate(z)?);
        let position = match (p.is_nan(), p.is_finite()) {
            (_, true) => Some(p),
            (true, _) if p.x.is_nan() && p.y.is_nan() && p.z.is_nan() => None,
            _ => return Err(at(format!("{name}: some coordinates are nan and some are not"))),
        };
        if landmarks.iter().any(|l| l.name == name) {
            return Err(at(format!("{name} is listed twice")));
        }
        landmarks.push(Landmark { name: name.to_string(), position });
    }
    Ok(landmarks)
}

/// Reads the landmark file at `path`.
pub fn read(path: &Path) -> Result<Vec<Landmark>, String> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| format!("{}: cannot read: {e}", messages::path(path)))?;
    parse(&text, path)
}

/// `landmarks.json`: the landmarks of a scan in its coordinates and in the canonical frame.
#[derive(Debug, Clone, Serialize)]
pub struct LandmarksFile {
    /// The landmark file's name.
    pub source: String,
    /// What was done with them.
    pub note: &'static str,
    /// Each landmark.
    pub landmarks: Vec<LandmarkEntry>,
}

/// One landmark of [`LandmarksFile`].
#[derive(Debug, Clone, Serialize)]
pub struct LandmarkEntry {
    /// Its name.
    pub name: String,
    /// In the scan's coordinates; null where the scanner did not find it.
    pub scan: Option<[f64; 3]>,
    /// In the canonical frame (mm, Z up, floor at 0).
    pub canonical_mm: Option<[f64; 3]>,
}

/// What [`LandmarksFile::note`] says.
const NOTE: &str =
    "read and checked; not used by the fit yet (it has no landmark input): carried for reference";

impl LandmarksFile {
    /// The landmarks of `source`, placed with the scan's `frame`.
    pub fn new(source: &Path, landmarks: &[Landmark], frame: &CanonicalFrame) -> Self {
        let name =
            source.file_name().map_or_else(String::new, |n| n.to_string_lossy().into_owned());
        let landmarks = landmarks
            .iter()
            .map(|l| LandmarkEntry {
                name: l.name.clone(),
                scan: l.position.map(|p| p.to_array()),
                canonical_mm: l.position.map(|p| frame.to_canonical(p).to_array()),
            })
            .collect();
        LandmarksFile { source: name, note: NOTE, landmarks }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_sharp_list_reads_and_bad_lines_are_named() {
        let path = Path::new("alice.txt");
        let text = "# SHARP\nsellion 0.01 1.62 0.09\n\nnavel nan nan NaN\n";
        let l = parse(text, path).unwrap();
        assert_eq!(l.len(), 2);
        assert_eq!(l[0].position, Some(DVec3::new(0.01, 1.62, 0.09)));
        assert_eq!(l[1].position, None);
        let err = |t: &str| parse(t, path).unwrap_err();
        assert_eq!(
            err("a 1 2\n"),
            "alice.txt line 1: expected 'name x y z', found 3 fields: 'a 1 2'"
        );
        assert!(err("a 1 2 x\n").contains("line 1: 'x' is not a coordinate"));
        assert!(err("a 1 2 inf\n").contains("'inf' is not a coordinate"));
        assert!(err("a 1 nan 3\n").contains("some coordinates are nan"));
        assert!(err("a 1 2 3\nb 1 2 3\na 1 2 3\n").contains("line 3: a is listed twice"));
    }
}
