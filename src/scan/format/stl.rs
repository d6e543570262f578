//! STL through `stl_io`, which also welds the corners that STL repeats per triangle.
//!
//! Binary or ASCII is decided by size first: a binary file is exactly `84 + 50 n` bytes for
//! the `n` its header declares. That catches the many binary files whose free-form header
//! starts with "solid" (which `stl_io` alone would take for ASCII) and truncated files.

use super::ReadError;
use crate::mesh::Mesh;
use glam::DVec3;
use std::io::Cursor;

const HEADER: usize = 84;
const TRIANGLE: usize = 50;

pub(super) fn read(bytes: &[u8]) -> Result<Mesh, ReadError> {
    let declared = bytes.get(80..84).map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as usize);
    let binary_size = declared.map(|n| HEADER as u64 + TRIANGLE as u64 * n as u64);
    let looks_ascii = bytes.starts_with(b"solid");
    let exact_binary = binary_size == Some(bytes.len() as u64);

    let indexed = if exact_binary || !looks_ascii {
        let (Some(n), Some(size)) = (declared, binary_size) else {
            return Err(ReadError::Truncated(format!(
                "{} bytes, shorter than the 84-byte binary STL header",
                bytes.len()
            )));
        };
        if (bytes.len() as u64) < size {
            return Err(ReadError::Truncated(format!(
                "the header declares {n} triangles ({size} bytes) but the file has {} bytes",
                bytes.len()
            )));
        }
        // stl_io picks ASCII for any file starting with "solid "; blank the (free-form) header
        // so that it reads the binary triangles.
        let mut copy = bytes[..size as usize].to_vec();
        copy[..80].fill(0);
        stl_io::read_stl(&mut Cursor::new(copy))
    } else {
        stl_io::read_stl(&mut Cursor::new(bytes))
    }
    .map_err(|e| ReadError::Malformed(e.to_string()))?;

    let positions = indexed
        .vertices
        .iter()
        .map(|v| DVec3::new(v[0].into(), v[1].into(), v[2].into()))
        .collect();
    let triangles = indexed.faces.iter().map(|f| f.vertices.map(|i| i as u32)).collect();
    Ok(Mesh::new(positions, triangles))
}

/// Binary STL (`f32` coordinates, as the format requires).
pub(super) fn encode(mesh: &Mesh) -> Vec<u8> {
    let triangles: Vec<stl_io::Triangle> = (0..mesh.triangles.len())
        .map(|t| {
            let n = mesh.scaled_normal(t).normalize_or_zero().as_vec3().to_array();
            let corners = mesh.corners(t).map(|p| stl_io::Vertex::new(p.as_vec3().to_array()));
            stl_io::Triangle { normal: stl_io::Normal::new(n), vertices: corners }
        })
        .collect();
    let mut out = Vec::with_capacity(HEADER + TRIANGLE * triangles.len());
    // Writing into a Vec cannot fail.
    let written = stl_io::write_stl(&mut out, triangles.iter());
    debug_assert!(written.is_ok(), "STL encoding into memory failed: {written:?}");
    out
}
