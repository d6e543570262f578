//! Mesh file formats: OBJ, PLY and STL in, and out.
//!
//! Readers parse bytes into a [`Mesh`] whose indices are all in range (anything else is a
//! [`ReadError`]); they never panic, whatever the bytes. Checks of the geometry itself (finite
//! coordinates, degenerate faces, components, holes) belong to [`crate::scan::clean`].
//! Writers go through [`crate::output::write_atomically`], so a crash never leaves half a file.

mod obj;
mod ply;
mod ply_binary;
mod stl;

use crate::mesh::Mesh;
use std::fmt;
use std::path::Path;

/// A mesh file format, chosen by file extension.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Format {
    /// Wavefront OBJ (read: polygons are triangulated; write: ASCII, exact `f64`).
    Obj,
    /// Stanford PLY (read: ASCII and binary, either endianness; write: binary little endian, `f64`).
    Ply,
    /// STL (read: ASCII and binary, corners welded; write: binary, `f32`).
    Stl,
}

impl Format {
    /// The format named by `path`'s extension (case-insensitive), if it is one we know.
    pub fn from_path(path: &Path) -> Option<Format> {
        let ext = path.extension()?.to_str()?.to_ascii_lowercase();
        match ext.as_str() {
            "obj" => Some(Format::Obj),
            "ply" => Some(Format::Ply),
            "stl" => Some(Format::Stl),
            _ => None,
        }
    }

    /// Parses `bytes` in this format.
    pub fn read(self, bytes: &[u8]) -> Result<Mesh, ReadError> {
        if bytes.is_empty() {
            return Err(ReadError::Empty);
        }
        let mesh = match self {
            Format::Obj => obj::read(bytes)?,
            Format::Ply => ply::read(bytes)?,
            Format::Stl => stl::read(bytes)?,
        };
        if mesh.triangles.is_empty() {
            return Err(ReadError::NoFaces);
        }
        Ok(mesh)
    }

    /// Encodes `mesh` in this format.
    pub fn encode(self, mesh: &Mesh) -> Vec<u8> {
        match self {
            Format::Obj => obj::encode(mesh),
            Format::Ply => ply::encode(mesh),
            Format::Stl => stl::encode(mesh),
        }
    }
}

impl fmt::Display for Format {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Format::Obj => "OBJ",
            Format::Ply => "PLY",
            Format::Stl => "STL",
        })
    }
}

/// Why bytes could not be read as a mesh.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ReadError {
    /// Zero bytes.
    #[error("the file is empty")]
    Empty,
    /// A binary file that ends before the data its header announces.
    #[error("truncated: {0}")]
    Truncated(String),
    /// Bytes that do not follow the format.
    #[error("malformed: {0}")]
    Malformed(String),
    /// A face that names a vertex the file does not have.
    #[error("face {face} refers to vertex {index}, but there are only {vertices} vertices")]
    IndexOutOfRange {
        /// Face number (0-based, in file order).
        face: usize,
        /// The offending vertex index (0-based).
        index: i64,
        /// How many vertices the file has.
        vertices: usize,
    },
    /// A well-formed file without any faces (a point cloud, or nothing).
    #[error("no faces: a body scan must be a triangle or polygon mesh")]
    NoFaces,
}

/// Checks that every index of `faces` names one of `vertex_count` vertices.
fn check_indices(faces: &[[u32; 3]], vertex_count: usize) -> Result<(), ReadError> {
    for (face, tri) in faces.iter().enumerate() {
        if let Some(&index) = tri.iter().find(|&&i| i as usize >= vertex_count) {
            return Err(ReadError::IndexOutOfRange {
                face,
                index: index.into(),
                vertices: vertex_count,
            });
        }
    }
    Ok(())
}

/// Splits a polygon into a triangle fan (polygons in scans are convex quads, nearly always).
fn fan(polygon: &[u32], out: &mut Vec<[u32; 3]>) {
    for k in 1..polygon.len().saturating_sub(1) {
        out.push([polygon[0], polygon[k], polygon[k + 1]]);
    }
}
