//! The numbers of a PLY payload one after the other, from binary bytes or ASCII words, and
//! the element walker that reads any layout through them. Every number read moves through the
//! file, so a walk ends within the file's length whatever its header declares.

use super::super::text::{Words, integer, number, shown};
use super::super::{ReadError, fan};
use super::header::{Element, Kind, Num};
use glam::DVec3;

/// A source of payload numbers. `Ok(None)`: the payload has ended.
pub(super) trait Values {
    /// The next number, of type `t`.
    fn scalar(&mut self, t: Num) -> Result<Option<f64>, ReadError>;
    /// The next number, of integer type `t` (a list length or a vertex index).
    fn integer(&mut self, t: Num) -> Result<Option<i64>, ReadError>;
}

/// Binary payload bytes.
pub(super) struct Bytes<'a> {
    pub(super) bytes: &'a [u8],
    pub(super) at: usize,
    pub(super) big_endian: bool,
}

impl<'a> Bytes<'a> {
    /// The next `n` bytes, if there are that many.
    pub(super) fn take(&mut self, n: usize) -> Option<&'a [u8]> {
        let chunk = self.bytes.get(self.at..self.at.checked_add(n)?)?;
        self.at += n;
        Some(chunk)
    }
}

impl Values for Bytes<'_> {
    fn scalar(&mut self, t: Num) -> Result<Option<f64>, ReadError> {
        let big_endian = self.big_endian;
        Ok(self.take(t.size()).map(|b| decode(b, t, big_endian)))
    }

    fn integer(&mut self, t: Num) -> Result<Option<i64>, ReadError> {
        let big_endian = self.big_endian;
        Ok(self.take(t.size()).map(|b| decode_integer(b, t, big_endian)))
    }
}

/// The number of type `t` at the start of `bytes` (which holds at least its size), as f64:
/// exact for every integer type.
pub(super) fn decode(bytes: &[u8], t: Num, big_endian: bool) -> f64 {
    match t {
        Num::F32 => f32::from_bits(unsigned(bytes, 4, big_endian) as u32).into(),
        Num::F64 => f64::from_bits(unsigned(bytes, 8, big_endian)),
        _ => decode_integer(bytes, t, big_endian) as f64,
    }
}

/// The integer of type `t` at the start of `bytes`; a float type is read as its value
/// rounded toward zero (the header check keeps floats out of lengths and indices).
pub(super) fn decode_integer(bytes: &[u8], t: Num, big_endian: bool) -> i64 {
    let u = unsigned(bytes, t.size(), big_endian);
    match t {
        Num::I8 => (u as u8 as i8).into(),
        Num::I16 => (u as u16 as i16).into(),
        Num::I32 => (u as u32 as i32).into(),
        Num::U8 | Num::U16 | Num::U32 => u as i64,
        Num::F32 | Num::F64 => decode(bytes, t, big_endian) as i64,
    }
}

/// The first `size` (1, 2, 4 or 8) bytes of `bytes` as an unsigned integer.
fn unsigned(bytes: &[u8], size: usize, big_endian: bool) -> u64 {
    fn read<const N: usize>(bytes: &[u8], big_endian: bool) -> [u8; N] {
        let mut b = bytes.first_chunk::<N>().copied().unwrap_or([0; N]);
        if big_endian {
            b.reverse();
        }
        b
    }
    match size {
        1 => bytes.first().copied().unwrap_or(0).into(),
        2 => u16::from_le_bytes(read(bytes, big_endian)).into(),
        4 => u32::from_le_bytes(read(bytes, big_endian)).into(),
        _ => u64::from_le_bytes(read(bytes, big_endian)),
    }
}

/// ASCII payload words.
pub(super) struct Text<'a> {
    pub(super) words: Words<'a>,
    /// The header's line count: payload lines are numbered from there, as in the file.
    pub(super) first_line: usize,
}

impl Text<'_> {
    fn located(&self, e: ReadError) -> ReadError {
        match e {
            ReadError::Line { line, problem } => ReadError::at(line + self.first_line, problem),
            e => e,
        }
    }
}

impl Values for Text<'_> {
    fn scalar(&mut self, _: Num) -> Result<Option<f64>, ReadError> {
        let Some(w) = self.words.next_word() else { return Ok(None) };
        number(w, self.words.line()).map(Some).map_err(|e| self.located(e))
    }

    fn integer(&mut self, _: Num) -> Result<Option<i64>, ReadError> {
        let Some(w) = self.words.next_word() else { return Ok(None) };
        integer(w, self.words.line()).map(Some).map_err(|e| self.located(e))
    }
}

/// What an element is to the mesh.
pub(super) enum Role {
    /// Vertices: the positions of the `x`, `y`, `z` properties.
    Vertex([usize; 3]),
    /// Faces: the position of the index list; indices must name one of `vertices`.
    Face { list: usize, vertices: usize },
    /// Anything else: read and dropped.
    Other,
}

/// What [`walk`] found.
#[derive(Default)]
pub(super) struct Found {
    pub(super) positions: Vec<DVec3>,
    pub(super) triangles: Vec<[u32; 3]>,
}

/// Reads every item of `element` from `values`, whatever its layout.
pub(super) fn walk(
    values: &mut impl Values,
    element: &Element,
    role: &Role,
    found: &mut Found,
) -> Result<(), ReadError> {
    let mut polygon: Vec<u32> = Vec::new();
    for item in 0..element.count {
        let ended = || {
            ReadError::Truncated(format!(
                "the data ends in item {item} of the {} {} element",
                element.count,
                element.shown()
            ))
        };
        let mut position = [0.0; 3];
        for (k, property) in element.properties.iter().enumerate() {
            match property.kind {
                Kind::Scalar(t) => {
                    let v = values.scalar(t)?.ok_or_else(ended)?;
                    if let Role::Vertex(xyz) = role
                        && let Some(axis) = xyz.iter().position(|&p| p == k)
                    {
                        position[axis] = v;
                    }
                }
                Kind::List { length, item: t } => {
                    let n = values.integer(length)?.ok_or_else(ended)?;
                    let n = u64::try_from(n).map_err(|_| {
                        let name = shown(property.name.as_bytes());
                        ReadError::Malformed(format!(
                            "item {item} of {}: list {name} has {n} entries",
                            element.shown()
                        ))
                    })?;
                    let indices = match role {
                        Role::Face { list, vertices } if *list == k => Some(*vertices),
                        _ => None,
                    };
                    polygon.clear();
                    for _ in 0..n {
                        let Some(vertices) = indices else {
                            values.scalar(t)?.ok_or_else(ended)?;
                            continue;
                        };
                        let index = values.integer(t)?.ok_or_else(ended)?;
                        match u32::try_from(index) {
                            Ok(i) if (i as usize) < vertices => polygon.push(i),
                            _ => {
                                return Err(ReadError::IndexOutOfRange {
                                    face: item,
                                    index,
                                    vertices,
                                });
                            }
                        }
                    }
                    fan(&polygon, &mut found.triangles);
                }
            }
        }
        if let Role::Vertex(_) = role {
            found.positions.push(DVec3::from_array(position));
        }
    }
    Ok(())
}

/// The name of `element` and why it is not what the mesh needs.
pub(super) fn unusable(element: &Element, why: &str) -> ReadError {
    ReadError::Malformed(format!("the {} element {why}", shown(element.name.as_bytes())))
}
