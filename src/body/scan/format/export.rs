//! The description of an output mesh file — format, units, up axis, header comments — used by
//! every command that writes a mesh, so that all of them write the same way.
//!
//! Coordinates are rounded to [`RESOLUTION_MM`] and written as the shortest decimal that reads
//! back to the rounded value (`812.345`, not `812.3450000000001`): a 0.001 mm grid is a
//! hundred times finer than a scanner resolves, and keeps OBJ files small. The header names
//! the units and axes (OBJ `#` lines, PLY `comment` lines, glb asset `extras`; see
//! [`super::MeshFile::comments`]), then the caller's own comment lines.

use super::Format;
use crate::body::mesh::Mesh;
use crate::body::scan::frame::{CanonicalFrame, FileFrame, Units};
use glam::DVec3;

/// The grid output coordinates are rounded to, in mm (issue 12: 0.001 mm).
pub const RESOLUTION_MM: f64 = 0.001;

/// The file's up axis, for a mesh in the canonical frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum UpAxis {
    /// Z up (the canonical frame; CAD and 3D-printing tools).
    Z,
    /// Y up (glTF, Blender's OBJ import, CLO3D, game engines): the canonical frame turned by
    /// (x, y, z) -> (x, z, -y), so the subject faces +Z and +X stays the subject's left.
    Y,
}

/// Where an output mesh's coordinates are.
#[derive(Debug, Clone, PartialEq)]
pub enum Placement {
    /// The canonical body frame (mm, Z up, floor at z = 0, +X = the subject's left, facing
    /// -Y), written in `units` with `up` as the file's up axis.
    Canonical {
        /// The file's unit.
        units: Units,
        /// The file's up axis.
        up: UpAxis,
    },
    /// Coordinates as the mesh has them, which are in `units`; `frame` says what they are,
    /// for the header ("the scan's own frame, Y up").
    AsIs {
        /// The unit the coordinates are in.
        units: Units,
        /// A description of the axes.
        frame: String,
    },
}

impl Placement {
    /// How the file's coordinates map back to the canonical frame, for a canonical placement
    /// (`None` for coordinates as they are: only their owner knows what they are).
    pub fn file_frame(&self) -> Option<FileFrame> {
        let Placement::Canonical { units, up } = self else { return None };
        let rotation = match up {
            UpAxis::Z => [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
            // The inverse of (x, y, z) -> (x, z, -y).
            UpAxis::Y => [[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]],
        };
        Some(FileFrame { units: *units, rotation, translation: [0.0; 3] })
    }
}

/// A mesh file to write.
#[derive(Debug, Clone, PartialEq)]
pub struct Export {
    /// The format.
    pub format: Format,
    /// Units and axes.
    pub placement: Placement,
    /// Lines added to the header after units and axes (`key: value` by convention).
    pub comments: Vec<String>,
}

/// An export that its format cannot carry.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ExportError {
    /// glTF fixes units and axes.
    #[error(
        "glb files are in metres with Y up by definition (glTF 2.0); use --units m --up y or leave them out"
    )]
    GlbFrame,
}

impl Export {
    /// An export of a canonical-frame mesh in `format` with that format's usual frame: glb in
    /// metres with Y up (as glTF requires), the others in mm with Z up (the canonical frame).
    pub fn canonical(format: Format) -> Export {
        let (units, up) = match format {
            Format::Glb => (Units::M, UpAxis::Y),
            _ => (Units::Mm, UpAxis::Z),
        };
        Export { format, placement: Placement::Canonical { units, up }, comments: Vec::new() }
    }

    /// An export in `format` at `placement`, checked: glb must be canonical, metres, Y up.
    pub fn new(format: Format, placement: Placement) -> Result<Export, ExportError> {
        let glb_frame = Placement::Canonical { units: Units::M, up: UpAxis::Y };
        if format == Format::Glb && placement != glb_frame {
            return Err(ExportError::GlbFrame);
        }
        Ok(Export { format, placement, comments: Vec::new() })
    }

    /// The same export with `comments` added to the header.
    pub fn with_comments(mut self, comments: impl IntoIterator<Item = String>) -> Export {
        self.comments.extend(comments);
        self
    }

    /// `stem` with this format's extension: `mannequin.obj`.
    pub fn file_name(&self, stem: &str) -> String {
        format!("{stem}.{}", self.format.extension())
    }

    /// The header lines: the writer, units, axes, then [`Export::comments`].
    pub fn header(&self) -> Vec<String> {
        let mut lines = vec![format!("written by dressform {}", env!("CARGO_PKG_VERSION"))];
        match &self.placement {
            Placement::Canonical { units, up } => {
                let (up, facing, floor) = match up {
                    UpAxis::Z => ("+z", "-y", "z"),
                    UpAxis::Y => ("+y", "+z", "y"),
                };
                lines.push(format!("units: {units}"));
                lines.push(format!("up: {up}"));
                lines.push(format!(
                    "frame: +x = the subject's left, the subject faces {facing}, floor at {floor} = 0"
                ));
            }
            Placement::AsIs { units, frame } => {
                lines.push(format!("units: {units}"));
                lines.push(format!("frame: {frame}"));
            }
        }
        lines.extend(self.comments.iter().cloned());
        lines
    }

    /// `mesh`, in the canonical frame of a scan whose frame is `scan`, as it goes into this
    /// file, with how the file's coordinates map back to the canonical frame: a canonical
    /// placement keeps the coordinates; coordinates "as they are" go back into the scan's frame.
    pub fn place(&self, mesh: &Mesh, scan: &CanonicalFrame) -> (Mesh, FileFrame) {
        match self.placement.file_frame() {
            Some(frame) => (mesh.clone(), frame),
            None => (mesh.map_positions(|p| scan.to_scan(p)), scan.file_frame()),
        }
    }

    /// `mesh` encoded: moved into the file's frame, rounded to [`RESOLUTION_MM`], with the
    /// header.
    pub fn encode(&self, mesh: &Mesh) -> Vec<u8> {
        let (units, up) = match &self.placement {
            Placement::Canonical { units, up } => (*units, Some(*up)),
            Placement::AsIs { units, .. } => (*units, None),
        };
        // Steps of RESOLUTION_MM per file unit: 1e3 for mm, 1e6 for m.
        let steps = units.mm() / RESOLUTION_MM;
        let round = |c: f64| (c * steps).round() / steps + 0.0; // + 0.0: no "-0"
        let placed = mesh.map_positions(|p| {
            let p = match up {
                Some(up) => turned(p, up) / units.mm(),
                None => p,
            };
            DVec3::new(round(p.x), round(p.y), round(p.z))
        });
        self.format.encode_with(&placed, &self.header())
    }
}

/// A canonical point with `up` as the up axis (still in mm).
fn turned(p: DVec3, up: UpAxis) -> DVec3 {
    match up {
        UpAxis::Z => p,
        UpAxis::Y => DVec3::new(p.x, p.z, -p.y),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::body::scan::format::comment_value;

    fn triangle() -> Mesh {
        let p = [[1.23456789, -200.0004, 1700.0], [-0.0001, 0.1 + 0.2, 3.0], [0.0, 5.0, 0.0]];
        Mesh::new(p.iter().map(|&a| DVec3::from_array(a)).collect(), vec![[0, 1, 2]])
    }

    #[test]
    fn obj_in_metres_y_up_with_short_numbers_and_a_header() {
        let export =
            Export::new(Format::Obj, Placement::Canonical { units: Units::M, up: UpAxis::Y })
                .unwrap()
                .with_comments(["crotch: 812.5".to_string()]);
        let text = String::from_utf8(export.encode(&triangle())).unwrap();
        assert!(text.contains("v 0.001235 1.7 0.2\n"), "{text}");
        assert!(text.contains("v 0 0.003 -0.0003\n"), "{text}");
        let file = Format::Obj.decode(text.as_bytes()).unwrap();
        assert_eq!(comment_value(&file.comments, "units"), Some("m"));
        assert_eq!(comment_value(&file.comments, "up"), Some("+y"));
        assert_eq!(comment_value(&file.comments, "crotch"), Some("812.5"));
        assert!(!text.contains("-0 "), "{text}");
    }

    #[test]
    fn rounding_is_to_a_thousandth_of_a_millimetre_in_every_unit() {
        for units in [Units::Mm, Units::Cm, Units::M] {
            let export =
                Export::new(Format::Ply, Placement::Canonical { units, up: UpAxis::Z }).unwrap();
            let back = Format::Ply.read(&export.encode(&triangle())).unwrap();
            for (a, b) in back.positions.iter().zip(&triangle().positions) {
                assert!((*a * units.mm() - *b).abs().max_element() <= 0.5 * RESOLUTION_MM + 1e-9);
            }
        }
    }

    #[test]
    fn glb_is_metres_y_up_only() {
        assert_eq!(
            Export::new(Format::Glb, Placement::Canonical { units: Units::Mm, up: UpAxis::Y }),
            Err(ExportError::GlbFrame)
        );
        let glb = Export::canonical(Format::Glb);
        assert_eq!(glb.placement, Placement::Canonical { units: Units::M, up: UpAxis::Y });
        assert_eq!(glb.file_name("mannequin"), "mannequin.glb");
    }
}
