//! Scan input: read a body mesh from a file, validate and clean it, and move it into the
//! canonical frame.
//!
//! ```text
//! file bytes --format--> Mesh --clean--> body Mesh --frame--> canonical body Mesh
//! ```

pub mod clean;
pub mod format;
pub mod frame;

use crate::mesh::{Aabb, Mesh};
use clean::{CleanError, CleaningReport};
use format::{Format, ReadError};
use frame::{CanonicalFrame, FrameError, FrameOptions};
use std::path::{Path, PathBuf};

/// A body scan ready for the pipeline.
#[derive(Debug, Clone)]
pub struct Scan {
    /// Where it came from (a file path, or a description such as "synthetic body").
    pub source: PathBuf,
    /// Vertex count as read.
    pub raw_vertices: usize,
    /// Triangle count as read (polygons triangulated).
    pub raw_triangles: usize,
    /// What cleaning found and did.
    pub cleaning: CleaningReport,
    /// The scan's frame, and how it maps to the canonical one.
    pub frame: CanonicalFrame,
    /// The body in the canonical frame (mm, Z up, floor at 0, +X left, facing -Y).
    pub body: Mesh,
}

/// Why a scan could not be loaded. Every message starts with the file's name.
#[derive(Debug, thiserror::Error)]
pub enum ScanError {
    /// The file could not be opened or read.
    #[error("{}: cannot read: {source}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// What the operating system said.
        #[source]
        source: std::io::Error,
    },
    /// The extension names no format we read.
    #[error("{}: unknown mesh format; expected a .obj, .ply or .stl file", path.display())]
    UnknownFormat {
        /// The file.
        path: PathBuf,
    },
    /// The bytes are not a mesh in the format.
    #[error("{}: {format}: {error}", path.display())]
    Read {
        /// The file.
        path: PathBuf,
        /// The format it was read as.
        format: Format,
        /// What is wrong.
        error: ReadError,
    },
    /// The mesh is not usable as a body.
    #[error("{}: {error}", path.display())]
    Clean {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        error: CleanError,
    },
    /// The canonical frame could not be found.
    #[error("{}: {error}", path.display())]
    Frame {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        error: FrameError,
    },
}

/// Reads a mesh file in the format its extension names, without cleaning it.
pub fn read_mesh(path: &Path) -> Result<(Mesh, Format), ScanError> {
    let format =
        Format::from_path(path).ok_or_else(|| ScanError::UnknownFormat { path: path.into() })?;
    let bytes =
        FileBytes::open(path).map_err(|source| ScanError::Io { path: path.into(), source })?;
    let mesh = format.read(&bytes).map_err(|error| ScanError::Read {
        path: path.into(),
        format,
        error,
    })?;
    Ok((mesh, format))
}

/// A file's bytes: mapped into memory where the system allows it, read otherwise.
///
/// Mapping a million-triangle scan costs about a tenth of reading it (no copy, and no fresh
/// memory for the kernel to clear). The catch of any file mapping: if another program
/// truncates the file while it is being read, the process is stopped by SIGBUS. Scans reach
/// us as finished files, so the speed is worth it (ripgrep makes the same trade).
enum FileBytes {
    Mapped(memmap2::Mmap),
    Read(Vec<u8>),
}

impl FileBytes {
    fn open(path: &Path) -> std::io::Result<FileBytes> {
        let file = std::fs::File::open(path)?;
        // SAFETY: the map is read-only and dropped before we return to the caller; see the
        // type's documentation for what happens if the file shrinks meanwhile.
        match unsafe { memmap2::Mmap::map(&file) } {
            Ok(map) => Ok(FileBytes::Mapped(map)),
            Err(_) => std::fs::read(path).map(FileBytes::Read),
        }
    }
}

impl std::ops::Deref for FileBytes {
    type Target = [u8];
    fn deref(&self) -> &[u8] {
        match self {
            FileBytes::Mapped(map) => map,
            FileBytes::Read(bytes) => bytes,
        }
    }
}

/// Loads the scan at `path`: read, clean, canonical frame.
pub fn load(path: &Path, options: &FrameOptions) -> Result<Scan, ScanError> {
    let (mesh, _) = read_mesh(path)?;
    from_mesh(mesh, path, options)
}

/// Cleans `mesh` (as a scanner delivered it) and moves it into the canonical frame; `source`
/// names it in messages.
pub fn from_mesh(mesh: Mesh, source: &Path, options: &FrameOptions) -> Result<Scan, ScanError> {
    let (raw_vertices, raw_triangles) = (mesh.positions.len(), mesh.triangles.len());
    let (mut body, cleaning) =
        clean::clean(mesh).map_err(|error| ScanError::Clean { path: source.into(), error })?;
    let mut frame = frame::detect(&body, options)
        .map_err(|error| ScanError::Frame { path: source.into(), error })?;
    body.transform(|p| frame.to_canonical(p));
    frame.centre_on_torso(&mut body);
    Ok(Scan { source: source.into(), raw_vertices, raw_triangles, cleaning, frame, body })
}

/// Serialises a box as `{"min": [x, y, z], "max": [x, y, z]}`.
pub(crate) fn serialize_aabb<S: serde::Serializer>(b: &Aabb, s: S) -> Result<S::Ok, S::Error> {
    use serde::ser::SerializeStruct;
    let mut st = s.serialize_struct("Aabb", 2)?;
    st.serialize_field("min", &b.min.to_array())?;
    st.serialize_field("max", &b.max.to_array())?;
    st.end()
}
