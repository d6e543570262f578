//! Binary PLY elements whose items all have one size, decoded in parallel, record by record:
//! vertices of scalar properties, and faces that are all triangles (what scanners write).
//! This makes million-triangle scans load about ten times faster than a call per property.
//! Other layouts go through [`super::values::walk`].

use super::super::ReadError;
use super::header::{Element, Kind, Num};
use super::values::{Bytes, decode, decode_integer};
use glam::DVec3;
use rayon::prelude::*;
use std::sync::atomic::{AtomicBool, Ordering};

/// The size of an item of `element` and each scalar's offset in it, when it has no lists.
fn fixed_layout(element: &Element) -> Option<(usize, Vec<usize>)> {
    let mut offsets = Vec::with_capacity(element.properties.len());
    let mut size = 0;
    for p in &element.properties {
        let Kind::Scalar(t) = p.kind else { return None };
        offsets.push(size);
        size += t.size();
    }
    Some((size, offsets))
}

/// Moves past `element` if its items have one size (`None`, unmoved, otherwise). The header
/// check has made sure the bytes are there; if not, this is truncation.
pub(super) fn skip(bytes: &mut Bytes, element: &Element) -> Option<Result<(), ReadError>> {
    let (size, _) = fixed_layout(element)?;
    Some(take_all(bytes, element, size).map(|_| ()))
}

fn take_all<'a>(bytes: &mut Bytes<'a>, e: &Element, size: usize) -> Result<&'a [u8], ReadError> {
    let n = e.count.checked_mul(size);
    n.and_then(|n| bytes.take(n)).ok_or_else(|| {
        ReadError::Truncated(format!("the data ends inside the {} {} items", e.count, e.shown()))
    })
}

/// The positions of a vertex element without lists (`xyz`: the x, y, z properties).
pub(super) fn vertices(
    bytes: &mut Bytes,
    element: &Element,
    xyz: [usize; 3],
) -> Option<Result<Vec<DVec3>, ReadError>> {
    let (size, offsets) = fixed_layout(element)?;
    let big_endian = bytes.big_endian;
    let types = xyz.map(|k| match element.properties[k].kind {
        Kind::Scalar(t) => t,
        Kind::List { .. } => Num::F64,
    });
    let records = match take_all(bytes, element, size) {
        Ok(records) => records,
        Err(e) => return Some(Err(e)),
    };
    let at = xyz.map(|k| offsets[k]);
    // What scanners write (little-endian floats or doubles): one loop with nothing to decide
    // per value; any other layout through the general decoder.
    let positions = match (types, big_endian) {
        ([Num::F32, Num::F32, Num::F32], false) => decode_records(records, size, |r, axis| {
            f32::from_le_bytes(bytes_at(r, at[axis])).into()
        }),
        ([Num::F64, Num::F64, Num::F64], false) => {
            decode_records(records, size, |r, axis| f64::from_le_bytes(bytes_at(r, at[axis])))
        }
        _ => {
            decode_records(records, size, |r, axis| decode(&r[at[axis]..], types[axis], big_endian))
        }
    };
    Some(Ok(positions))
}

/// The `N` bytes at `at` in record `r` (zeros past its end: the layout keeps them inside).
fn bytes_at<const N: usize>(r: &[u8], at: usize) -> [u8; N] {
    r.get(at..).and_then(|b| b.first_chunk().copied()).unwrap_or([0; N])
}

/// Positions from vertex records of `size` bytes, `coordinate(record, axis)` each.
fn decode_records(
    records: &[u8],
    size: usize,
    coordinate: impl Fn(&[u8], usize) -> f64 + Sync,
) -> Vec<DVec3> {
    records
        .par_chunks_exact(size.max(1))
        .map(|r| DVec3::new(coordinate(r, 0), coordinate(r, 1), coordinate(r, 2)))
        .collect()
}

/// The triangles of a face element whose one list (at `list`) holds integer vertex indices,
/// when every face is a triangle; each index must name one of `vertices`. `None` (bytes
/// unmoved) when some face is not a triangle or the layout has more than one list.
pub(super) fn triangles(
    bytes: &mut Bytes,
    element: &Element,
    list: usize,
    vertices: usize,
) -> Option<Result<Vec<[u32; 3]>, ReadError>> {
    let (mut size, mut length_at, mut length_type, mut index_type) = (0, 0, Num::U8, Num::U32);
    for (k, p) in element.properties.iter().enumerate() {
        match p.kind {
            Kind::Scalar(t) => size += t.size(),
            Kind::List { length, item } if k == list => {
                (length_at, length_type, index_type) = (size, length, item);
                size += length.size() + 3 * item.size();
            }
            Kind::List { .. } => return None,
        }
    }
    let big_endian = bytes.big_endian;
    let all = bytes.bytes.get(bytes.at..bytes.at.checked_add(element.count.checked_mul(size)?)?)?;
    let first = length_at + length_type.size();
    let decoded = match (length_type, index_type, big_endian) {
        // What scanners write (a byte count, 32-bit indices, little-endian): nothing to decide
        // per value.
        (Num::U8, Num::U32 | Num::I32, false) => {
            let signed = index_type == Num::I32;
            let raw = |r: &[u8], k: usize| {
                let b = bytes_at(r, first + 4 * k);
                if signed { i32::from_le_bytes(b).into() } else { u32::from_le_bytes(b).into() }
            };
            check_and_decode(all, size, |r| r.get(length_at) == Some(&3), raw, vertices)
        }
        _ => {
            let triangle = |r: &[u8]| decode_integer(&r[length_at..], length_type, big_endian) == 3;
            let raw = |r: &[u8], k: usize| {
                decode_integer(&r[first + k * index_type.size()..], index_type, big_endian)
            };
            check_and_decode(all, size, triangle, raw, vertices)
        }
    };
    if decoded.is_some() {
        bytes.at += all.len();
    }
    decoded
}

/// Decodes triangle records in parallel, `None` where some record is not a `triangle`; one
/// pass decodes and checks, a bad index is only located (for the message) afterwards.
fn check_and_decode(
    all: &[u8],
    size: usize,
    triangle: impl Fn(&[u8]) -> bool + Sync,
    raw: impl Fn(&[u8], usize) -> i64 + Sync,
    vertices: usize,
) -> Option<Result<Vec<[u32; 3]>, ReadError>> {
    let in_range = |i: i64| usize::try_from(i).is_ok_and(|i| i < vertices);
    let bad = AtomicBool::new(false);
    let index = |r: &[u8], k: usize| {
        let i = raw(r, k);
        if in_range(i) {
            i as u32
        } else {
            bad.store(true, Ordering::Relaxed);
            u32::MAX
        }
    };
    // Collected by index (a collect into `Option<Vec>` loses the length and gathers pieces).
    let other = AtomicBool::new(false);
    let triangles: Vec<[u32; 3]> = all
        .par_chunks_exact(size)
        .map(|r| {
            if !triangle(r) {
                other.store(true, Ordering::Relaxed);
            }
            [index(r, 0), index(r, 1), index(r, 2)]
        })
        .collect();
    if other.load(Ordering::Relaxed) {
        return None;
    }
    if bad.load(Ordering::Relaxed) {
        for (face, r) in all.chunks_exact(size).enumerate() {
            if let Some(index) = (0..3).map(|k| raw(r, k)).find(|&i| !in_range(i)) {
                return Some(Err(ReadError::IndexOutOfRange { face, index, vertices }));
            }
        }
    }
    Some(Ok(triangles))
}
