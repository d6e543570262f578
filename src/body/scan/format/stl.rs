//! STL, binary and ASCII. STL repeats each corner per triangle; corners at the same position
//! are welded into one vertex (in order of first appearance).
//!
//! Binary or ASCII is decided by size first: a binary file is exactly `84 + 50 n` bytes for
//! the `n` its header declares. That catches the many binary files whose free-form header
//! starts with "solid" and truncated files.

use super::text::{Words, number, shown};
use super::{ReadError, fan};
use crate::body::mesh::Mesh;
use glam::DVec3;
use rayon::prelude::*;

/// The binary header: 80 free bytes and the triangle count.
const HEADER: usize = 84;
/// A binary triangle: normal, three corners (12 `f32`) and a 2-byte attribute.
const TRIANGLE: usize = 50;

/// The triangle count a binary header declares and the file size it implies.
fn binary_size(bytes: &[u8]) -> Option<(u32, u64)> {
    let n = u32::from_le_bytes(*bytes.get(80..84)?.first_chunk::<4>()?);
    Some((n, HEADER as u64 + TRIANGLE as u64 * u64::from(n)))
}

/// Whether `bytes` has exactly the size of the binary STL its header declares.
pub(super) fn is_exact_binary(bytes: &[u8]) -> bool {
    binary_size(bytes).is_some_and(|(_, size)| size == bytes.len() as u64)
}

pub(super) fn read(bytes: &[u8]) -> Result<Mesh, ReadError> {
    let ascii = bytes.trim_ascii_start().starts_with(b"solid");
    let mut mesh = if is_exact_binary(bytes) || !ascii { binary(bytes)? } else { text(bytes)? };
    mesh.weld_identical();
    Ok(mesh)
}

fn binary(bytes: &[u8]) -> Result<Mesh, ReadError> {
    let Some((n, size)) = binary_size(bytes) else {
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
    // Bytes after the declared triangles are ignored, as other readers do.
    let records = &bytes[HEADER..size as usize];
    let corner = |r: &[u8], k: usize| {
        let c = |i: usize| {
            let at = 12 + 12 * k + 4 * i;
            f64::from(f32::from_le_bytes([r[at], r[at + 1], r[at + 2], r[at + 3]]))
        };
        DVec3::new(c(0), c(1), c(2))
    };
    let positions: Vec<DVec3> = records
        .par_chunks_exact(TRIANGLE)
        .flat_map_iter(|r| (0..3).map(move |k| corner(r, k)))
        .collect();
    let triangles = (0..n).map(|t| [3 * t, 3 * t + 1, 3 * t + 2]).collect();
    Ok(Mesh::new(positions, triangles))
}

/// ASCII STL: `solid`, then facets (`facet normal` 3 numbers, `outer loop`, `vertex` 3
/// numbers per corner, `endloop`, `endfacet`), `endsolid`; several solids may follow each
/// other. A facet of more than three corners is fanned.
fn text(bytes: &[u8]) -> Result<Mesh, ReadError> {
    let mut words = Words::new(bytes);
    let mut mesh = Mesh::default();
    let mut corners: Vec<u32> = Vec::new();
    let unexpected = |words: &Words, found: Option<&[u8]>, expected: &str| match found {
        Some(w) => ReadError::at(words.line(), format!("expected {expected}, found {}", shown(w))),
        None => ReadError::Truncated(format!("the file ends where {expected} should be")),
    };
    let expect = |words: &mut Words, expected: &[u8]| match words.next_word() {
        Some(w) if w.eq_ignore_ascii_case(expected) => Ok(()),
        other => Err(unexpected(words, other, &format!("'{}'", expected.escape_ascii()))),
    };
    let numbers = |words: &mut Words| -> Result<DVec3, ReadError> {
        let mut p = [0.0; 3];
        for c in &mut p {
            let w = words.next_word().ok_or_else(|| unexpected(words, None, "a number"))?;
            *c = number(w, words.line())?;
        }
        Ok(DVec3::from_array(p))
    };
    while let Some(w) = words.next_word() {
        if w.eq_ignore_ascii_case(b"solid") || w.eq_ignore_ascii_case(b"endsolid") {
            words.skip_line(); // the solid's name
            continue;
        }
        if !w.eq_ignore_ascii_case(b"facet") {
            return Err(unexpected(&words, Some(w), "'facet'"));
        }
        expect(&mut words, b"normal")?;
        numbers(&mut words)?;
        expect(&mut words, b"outer")?;
        expect(&mut words, b"loop")?;
        corners.clear();
        loop {
            match words.next_word() {
                Some(w) if w.eq_ignore_ascii_case(b"vertex") => {
                    corners.push(mesh.positions.len() as u32);
                    mesh.positions.push(numbers(&mut words)?);
                }
                Some(w) if w.eq_ignore_ascii_case(b"endloop") => break,
                other => return Err(unexpected(&words, other, "'vertex' or 'endloop'")),
            }
        }
        if corners.len() < 3 {
            let n = corners.len();
            return Err(ReadError::at(words.line(), format!("a facet needs 3 corners, found {n}")));
        }
        fan(&corners, &mut mesh.triangles);
        expect(&mut words, b"endfacet")?;
    }
    Ok(mesh)
}

/// Binary STL (`f32` coordinates, as the format requires); the free header carries the first
/// comments that fit in its 80 bytes.
pub(super) fn encode(mesh: &Mesh, comments: &[String]) -> Vec<u8> {
    let mut out = Vec::with_capacity(HEADER + TRIANGLE * mesh.triangles.len());
    // Not "solid...": that would make readers take it for ASCII.
    let mut header = String::from("binary STL");
    for c in comments {
        header.push_str("; ");
        header.push_str(c);
    }
    let mut free = [b' '; 80];
    let text: Vec<u8> =
        header.bytes().filter(|b| b.is_ascii_graphic() || *b == b' ').take(80).collect();
    free[..text.len()].copy_from_slice(&text);
    out.extend_from_slice(&free);
    out.extend_from_slice(&(mesh.triangles.len() as u32).to_le_bytes());
    for t in 0..mesh.triangles.len() {
        let normal = mesh.scaled_normal(t).normalize_or_zero();
        for v in std::iter::once(normal).chain(mesh.corners(t)) {
            for c in v.as_vec3().to_array() {
                out.extend_from_slice(&c.to_le_bytes());
            }
        }
        out.extend_from_slice(&[0, 0]);
    }
    out
}
