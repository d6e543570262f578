//! Scan input: read a body mesh from a file, validate and clean it, and move it into the
//! canonical frame.
//!
//! ```text
//! file bytes --format--> Mesh --clean--> body Mesh --frame--> canonical body Mesh
//! ```
//!
//! [`prepare`] is the commands' prologue on top of that: the scan loaded, its warnings
//! gathered and its body denoised.

pub mod carried;
pub mod clean;
pub mod format;
pub mod frame;
pub mod prepare;

use crate::body::mesh::{Aabb, Mesh};
use crate::messages;
use carried::CarriedBody;
use clean::{CleanError, CleaningReport};
use format::{Format, MeshFile, ReadError};
use frame::{CanonicalFrame, FileFrame, FrameError, FrameOptions};
pub use prepare::{PreparedScan, ScanOptions, TopologyCheck, prepare, prepare_then};
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
    /// The comments of the file's header (see [`MeshFile::comments`]); none for a mesh that
    /// came from no file.
    pub comments: Vec<String>,
    /// What the header of a file dressform wrote (a mannequin) says about the body: its
    /// frame (used instead of detecting one), landmarks and levels.
    pub carried: Option<CarriedBody>,
}

impl Scan {
    /// The one-line error of this scan, which could not be processed because of `e`: the
    /// file, and, when its units were detected and its size is unusual, the units assumed
    /// and how to override them ([`CanonicalFrame::units_hint`]; first, as the likely
    /// cause), then `e`.
    pub fn failed(&self, e: impl std::fmt::Display) -> String {
        let file = messages::path(&self.source);
        match self.frame.units_hint() {
            Some(hint) => format!("{file} ({hint}): {e}"),
            None => format!("{file}: {e}"),
        }
    }
}

/// Why a scan could not be loaded. Every message starts with the file's name.
#[derive(Debug, thiserror::Error)]
pub enum ScanError {
    /// The file could not be opened or read.
    #[error("{}: cannot read: {source}", messages::path(path))]
    Io {
        /// The file.
        path: PathBuf,
        /// What the operating system said.
        #[source]
        source: std::io::Error,
    },
    /// Not a regular file (a directory, a FIFO, a device): reading it could block forever or
    /// never end.
    #[error("{}: {what}, not a regular file", messages::path(path))]
    NotAFile {
        /// The file.
        path: PathBuf,
        /// What it is.
        what: &'static str,
    },
    /// The extension names no format we read.
    #[error(
        "{}: unknown mesh format; expected a .obj, .ply, .stl or .glb file",
        messages::path(path)
    )]
    UnknownFormat {
        /// The file.
        path: PathBuf,
    },
    /// The bytes are not a mesh in the format.
    #[error("{}: {format}: {error}", messages::path(path))]
    Read {
        /// The file.
        path: PathBuf,
        /// The format it was read as.
        format: Format,
        /// What is wrong.
        error: ReadError,
    },
    /// The mesh is not usable as a body.
    #[error("{}: {error}", messages::path(path))]
    Clean {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        error: CleanError,
    },
    /// The header of a file dressform wrote is unusable.
    #[error("{}: {error}", messages::path(path))]
    Header {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        error: String,
    },
    /// The canonical frame could not be found.
    #[error("{}: {error}", messages::path(path))]
    Frame {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        error: FrameError,
    },
}

/// Reads a mesh file in the format its extension names, without cleaning it.
pub fn read_mesh(path: &Path) -> Result<(Mesh, Format), ScanError> {
    read_mesh_file(path).map(|(file, format)| (file.mesh, format))
}

/// Reads a mesh file in the format its extension names, with its header comments, without
/// cleaning it.
pub fn read_mesh_file(path: &Path) -> Result<(MeshFile, Format), ScanError> {
    let format =
        Format::from_path(path).ok_or_else(|| ScanError::UnknownFormat { path: path.into() })?;
    let bytes = FileBytes::open(path)?;
    let file = format.decode(&bytes).map_err(|error| ScanError::Read {
        path: path.into(),
        format,
        error,
    })?;
    Ok((file, format))
}

/// A file's bytes: mapped into memory where the system allows it, read otherwise.
///
/// Mapping a million-triangle scan costs about a tenth of reading it (no copy, and no fresh
/// memory for the kernel to clear). The catch of any file mapping: if another program
/// truncates the file while it is being read, the process is stopped by SIGBUS. Scans reach
/// us as finished files, so the speed is worth it (ripgrep makes the same trade); files
/// smaller than [`MAP_FROM`] are copied instead, which keeps the risk to large scans.
enum FileBytes {
    Mapped(memmap2::Mmap),
    Read(Vec<u8>),
}

/// Files from this size on are mapped rather than copied (a copy of a few pages costs less
/// than setting up a mapping).
const MAP_FROM: u64 = 1 << 20;

impl FileBytes {
    /// Opens `path` if it is a regular file (or a link to one). It is opened without waiting
    /// (a FIFO with no writer would block a plain open forever), then checked.
    fn open(path: &Path) -> Result<FileBytes, ScanError> {
        let io = |source| ScanError::Io { path: path.into(), source };
        let mut options = std::fs::OpenOptions::new();
        options.read(true);
        #[cfg(unix)]
        std::os::unix::fs::OpenOptionsExt::custom_flags(&mut options, libc::O_NONBLOCK);
        let file = options.open(path).map_err(io)?;
        let meta = file.metadata().map_err(io)?;
        if !meta.is_file() {
            return Err(ScanError::NotAFile { path: path.into(), what: kind_of(&meta) });
        }
        if meta.len() < MAP_FROM {
            let mut bytes = Vec::with_capacity(meta.len() as usize);
            std::io::Read::read_to_end(&mut &file, &mut bytes).map_err(io)?;
            return Ok(FileBytes::Read(bytes));
        }
        // SAFETY: the map is read-only and dropped before we return to the caller; see the
        // type's documentation for what happens if the file shrinks meanwhile.
        match unsafe { memmap2::Mmap::map(&file) } {
            Ok(map) => Ok(FileBytes::Mapped(map)),
            Err(_) => std::fs::read(path).map(FileBytes::Read).map_err(io),
        }
    }
}

/// What a file that is not a regular one is.
fn kind_of(meta: &std::fs::Metadata) -> &'static str {
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        let t = meta.file_type();
        if t.is_fifo() {
            return "a FIFO (named pipe)";
        }
        if t.is_char_device() || t.is_block_device() {
            return "a device";
        }
        if t.is_socket() {
            return "a socket";
        }
    }
    if meta.is_dir() { "a directory" } else { "a special file" }
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

/// Loads the scan at `path`: read, clean, canonical frame (the one its header states, for a
/// file dressform wrote; see [`carried`]).
pub fn load(path: &Path, options: &FrameOptions) -> Result<Scan, ScanError> {
    let (file, _) = read_mesh_file(path)?;
    from_file(file, path, options)
}

/// Loads a scan from `bytes` in the format `source`'s extension names (`source` names it in
/// messages): read, clean, canonical frame.
pub fn from_bytes(bytes: &[u8], source: &Path, options: &FrameOptions) -> Result<Scan, ScanError> {
    let format = Format::from_path(source)
        .ok_or_else(|| ScanError::UnknownFormat { path: source.into() })?;
    let file = format.decode(bytes).map_err(|error| ScanError::Read {
        path: source.into(),
        format,
        error,
    })?;
    from_file(file, source, options)
}

/// [`from_mesh`] for a mesh read from a file: a header stating the body's frame (a file
/// dressform wrote) takes the place of detecting it, and `options` are not needed.
fn from_file(file: MeshFile, source: &Path, options: &FrameOptions) -> Result<Scan, ScanError> {
    let carried = CarriedBody::from_comments(&file.comments)
        .map_err(|error| ScanError::Header { path: source.into(), error })?;
    let mut scan = match carried {
        None => from_mesh(file.mesh, source, options)?,
        Some(carried) => {
            let mut scan = cleaned_and_placed(file.mesh, source, Placing::Stated(&carried.frame))?;
            scan.carried = Some(carried);
            scan
        }
    };
    scan.comments = file.comments;
    Ok(scan)
}

/// Cleans `mesh` (as a scanner delivered it) and moves it into the canonical frame; `source`
/// names it in messages.
pub fn from_mesh(mesh: Mesh, source: &Path, options: &FrameOptions) -> Result<Scan, ScanError> {
    cleaned_and_placed(mesh, source, Placing::Detected(options))
}

/// How a scan finds its canonical frame.
enum Placing<'a> {
    /// Detected (see [`frame::detect`]) with these options, then centred on the torso.
    Detected(&'a FrameOptions),
    /// As the file's header states it (a file dressform wrote).
    Stated(&'a FileFrame),
}

/// The one path of every scan: `mesh` cleaned, then moved into the canonical frame, found as
/// `placing` says. A detected frame's survey of the body is taken in the cleaning's pass over
/// the triangles ([`clean::clean_surveyed`]) when the cleaning drops none.
fn cleaned_and_placed(mesh: Mesh, source: &Path, placing: Placing) -> Result<Scan, ScanError> {
    let (raw_vertices, raw_triangles) = (mesh.positions.len(), mesh.triangles.len());
    let clean_error = |error| ScanError::Clean { path: source.into(), error };
    let (body, cleaning, frame) = match placing {
        Placing::Detected(options) => {
            let (mut body, cleaning, survey) = clean::clean_surveyed(mesh).map_err(clean_error)?;
            let survey = survey.unwrap_or_else(|| frame::Survey::of(&body));
            let mut frame = frame::detect_surveyed(&body, survey, options)
                .map_err(|error| ScanError::Frame { path: source.into(), error })?;
            body.transform(|p| frame.to_canonical(p));
            frame.centre_on_torso(&mut body);
            (body, cleaning, frame)
        }
        Placing::Stated(stated) => {
            let (mut body, cleaning) = clean::clean(mesh).map_err(clean_error)?;
            let frame = CanonicalFrame::stated(stated, &body).map_err(|e| {
                let error = format!("header line '{}:': frame.{e}", carried::HEADER_KEY);
                ScanError::Header { path: source.into(), error }
            })?;
            body.transform(|p| frame.to_canonical(p));
            (body, cleaning, frame)
        }
    };
    Ok(Scan {
        source: source.into(),
        raw_vertices,
        raw_triangles,
        cleaning,
        frame,
        body,
        comments: Vec::new(),
        carried: None,
    })
}

/// Serialises a box as `{"min": [x, y, z], "max": [x, y, z]}`.
pub(crate) fn serialize_aabb<S: serde::Serializer>(b: &Aabb, s: S) -> Result<S::Ok, S::Error> {
    use serde::ser::SerializeStruct;
    let mut st = s.serialize_struct("Aabb", 2)?;
    st.serialize_field("min", &b.min.to_array())?;
    st.serialize_field("max", &b.max.to_array())?;
    st.end()
}
