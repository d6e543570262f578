//! Mesh file formats: OBJ, PLY, STL and glb (binary glTF), in and out.
//!
//! Readers parse bytes into a [`MeshFile`]: a [`Mesh`] whose indices are all in range, and
//! the comments of the file's header (see [`MeshFile::comments`]). Whatever the bytes, a
//! reader returns in time linear in their length, allocates no more than they can fill, and
//! never panics; anything wrong is a one-line [`ReadError`]. Checks of the geometry itself
//! (finite coordinates, degenerate faces, components, holes) belong to [`crate::body::scan::clean`].
//!
//! Readers are written here rather than taken from `tobj`, `ply-rs-bw` and `stl_io`: those
//! allocate what a header declares before reading it (a 171-byte PLY aborted the process),
//! loop forever on property-less PLY elements, and report neither line numbers nor header
//! comments.
//!
//! Writers: [`Export`] describes an output mesh file (format, units, up axis, header comments)
//! for every command that writes one; [`Format::encode`] writes coordinates exactly as given.

mod export;
mod glb;
mod obj;
mod ply;
mod sniff;
mod stl;
mod text;

pub use export::{Export, ExportError, Placement, UpAxis};

use crate::body::mesh::Mesh;
use std::fmt;
use std::path::Path;

/// A mesh file format, chosen by file extension.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Format {
    /// Wavefront OBJ (read: polygons are triangulated; write: ASCII, shortest round trip).
    Obj,
    /// Stanford PLY (read: ASCII and binary, either endianness; write: binary little endian, `f64`).
    Ply,
    /// STL (read: ASCII and binary, corners welded; write: binary, `f32`).
    Stl,
    /// Binary glTF 2.0 (read: the triangles of every mesh in the scene, placed by their nodes;
    /// write: one mesh, `f32` positions, `u32` indices).
    Glb,
}

/// A mesh as read from a file, with its header comments.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct MeshFile {
    /// The mesh, in the file's coordinates.
    pub mesh: Mesh,
    /// The comments of the file's header, in order, each without its comment marker: OBJ's
    /// `#` lines before the first statement (one space after `#` dropped), PLY's `comment`
    /// lines, glb's `"comments"` string arrays in the `extras` of the asset and of the nodes.
    /// STL has none. dressform writes `key: value` lines (see [`comment_value`]).
    pub comments: Vec<String>,
}

/// The value of the first `key: value` line among `comments` (both sides trimmed), as
/// [`Export`] writes them (`units: mm`, `up: +z`).
pub fn comment_value<'a>(comments: &'a [String], key: &str) -> Option<&'a str> {
    comments.iter().find_map(|c| {
        let (k, v) = c.split_once(':')?;
        (k.trim() == key).then(|| v.trim())
    })
}

impl Format {
    /// Every format, in the order the documentation lists them.
    pub const ALL: [Format; 4] = [Format::Obj, Format::Ply, Format::Stl, Format::Glb];

    /// The format named by `path`'s extension (case-insensitive), if it is one we know.
    pub fn from_path(path: &Path) -> Option<Format> {
        let ext = path.extension()?.to_str()?.to_ascii_lowercase();
        Format::ALL.into_iter().find(|f| f.extension() == ext)
    }

    /// The file extension (lower case, without the dot).
    pub fn extension(self) -> &'static str {
        match self {
            Format::Obj => "obj",
            Format::Ply => "ply",
            Format::Stl => "stl",
            Format::Glb => "glb",
        }
    }

    /// Parses `bytes` in this format: the mesh and the header comments.
    pub fn decode(self, bytes: &[u8]) -> Result<MeshFile, ReadError> {
        if bytes.is_empty() {
            return Err(ReadError::Empty);
        }
        if let Some(what) = sniff::not_a_mesh(bytes, self) {
            return Err(ReadError::NotAMesh(what));
        }
        let file = match self {
            Format::Obj => obj::read(bytes)?,
            Format::Ply => ply::read(bytes)?,
            Format::Stl => MeshFile { mesh: stl::read(bytes)?, comments: Vec::new() },
            Format::Glb => glb::read(bytes)?,
        };
        if file.mesh.triangles.is_empty() {
            return Err(ReadError::NoFaces);
        }
        let MeshFile { mesh: Mesh { positions, triangles }, comments } = file;
        let mesh =
            Mesh::try_new(positions, triangles).map_err(|bad| ReadError::IndexOutOfRange {
                face: bad.triangle,
                index: i64::from(bad.index),
                vertices: bad.vertices,
            })?;
        Ok(MeshFile { mesh, comments })
    }

    /// Parses `bytes` in this format (the mesh only).
    pub fn read(self, bytes: &[u8]) -> Result<Mesh, ReadError> {
        self.decode(bytes).map(|file| file.mesh)
    }

    /// Encodes `mesh` in this format with its coordinates exactly as given (OBJ and PLY read
    /// back bit for bit; STL and glb store `f32`). Files for users go through [`Export`].
    pub fn encode(self, mesh: &Mesh) -> Vec<u8> {
        self.encode_with(mesh, &["written by dressform".to_string()])
    }

    /// Encodes `mesh` with `comments` in its header (STL: none).
    fn encode_with(self, mesh: &Mesh, comments: &[String]) -> Vec<u8> {
        match self {
            Format::Obj => obj::encode(mesh, comments),
            Format::Ply => ply::encode(mesh, comments),
            Format::Stl => stl::encode(mesh, comments),
            Format::Glb => glb::encode(mesh, comments),
        }
    }
}

impl fmt::Display for Format {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Format::Obj => "OBJ",
            Format::Ply => "PLY",
            Format::Stl => "STL",
            Format::Glb => "glb",
        })
    }
}

/// Why bytes could not be read as a mesh.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ReadError {
    /// Zero bytes.
    #[error("the file is empty")]
    Empty,
    /// Plainly not a mesh in this format (an archive, an image, UTF-16 text, another format).
    #[error("{0}")]
    NotAMesh(String),
    /// A file that ends before the data its header announces.
    #[error("truncated: {0}")]
    Truncated(String),
    /// Bytes that do not follow the format.
    #[error("malformed: {0}")]
    Malformed(String),
    /// A problem on a line of a text file.
    #[error("line {line}: {problem}")]
    Line {
        /// Line number, from 1.
        line: usize,
        /// What is wrong there.
        problem: String,
    },
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

impl ReadError {
    /// A problem on line `line`.
    fn at(line: usize, problem: impl Into<String>) -> ReadError {
        ReadError::Line { line, problem: problem.into() }
    }
}

/// `comment` as one header line: line breaks become spaces, other control characters are
/// escaped.
fn one_line(comment: &str) -> String {
    let flat: String =
        comment.chars().map(|c| if c == '\n' || c == '\r' { ' ' } else { c }).collect();
    crate::messages::quote(flat.as_bytes(), usize::MAX)
}

/// Splits a polygon into a triangle fan (polygons in scans are convex quads, nearly always),
/// in time linear in its size.
fn fan(polygon: &[u32], out: &mut Vec<[u32; 3]>) {
    for k in 1..polygon.len().saturating_sub(1) {
        out.push([polygon[0], polygon[k], polygon[k + 1]]);
    }
}
