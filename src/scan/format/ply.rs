//! Stanford PLY through `ply-rs-bw` (the maintained fork of `ply-rs`): the `vertex` element's
//! `x`, `y`, `z` (any numeric type) and the `face` element's `vertex_indices` (or
//! `vertex_index`) list; other elements and properties are skipped. Elements are parsed
//! straight into small structs (no per-element hash maps), which keeps large scans fast.

use super::{ReadError, check_indices, fan};
use crate::mesh::Mesh;
use glam::DVec3;
use ply_rs_bw::parser::{ParseError, Parser, Reader};
use ply_rs_bw::ply::{
    Addable, BeginList, ElementDef, Encoding, Header, PropertyAccess, PropertyAccessResult,
    PropertyDef, PropertyType, ScalarType,
};
use ply_rs_bw::writer::Writer;

/// A vertex: its position; `set` records which coordinates the file gave.
#[derive(Default)]
struct PlyVertex {
    position: [f64; 3],
    set: u8,
}

impl PlyVertex {
    fn set_coordinate(&mut self, name: &str, value: f64) -> PropertyAccessResult {
        let axis = match name {
            "x" => 0,
            "y" => 1,
            "z" => 2,
            _ => return PropertyAccessResult::Ignored,
        };
        self.position[axis] = value;
        self.set |= 1 << axis;
        PropertyAccessResult::Set
    }
}

impl PropertyAccess for PlyVertex {
    fn new() -> Self {
        PlyVertex::default()
    }
    fn set_char(&mut self, name: &str, v: i8) -> PropertyAccessResult {
        self.set_coordinate(name, v.into())
    }
    fn set_uchar(&mut self, name: &str, v: u8) -> PropertyAccessResult {
        self.set_coordinate(name, v.into())
    }
    fn set_short(&mut self, name: &str, v: i16) -> PropertyAccessResult {
        self.set_coordinate(name, v.into())
    }
    fn set_ushort(&mut self, name: &str, v: u16) -> PropertyAccessResult {
        self.set_coordinate(name, v.into())
    }
    fn set_int(&mut self, name: &str, v: i32) -> PropertyAccessResult {
        self.set_coordinate(name, v.into())
    }
    fn set_uint(&mut self, name: &str, v: u32) -> PropertyAccessResult {
        self.set_coordinate(name, v.into())
    }
    fn set_float(&mut self, name: &str, v: f32) -> PropertyAccessResult {
        self.set_coordinate(name, v.into())
    }
    fn set_double(&mut self, name: &str, v: f64) -> PropertyAccessResult {
        self.set_coordinate(name, v)
    }
    fn get_double(&self, name: &str) -> Option<f64> {
        match name {
            "x" => Some(self.position[0]),
            "y" => Some(self.position[1]),
            "z" => Some(self.position[2]),
            _ => None,
        }
    }
}

/// A face: its vertex indices as signed integers, so that negative ones can be reported.
#[derive(Default)]
struct PlyFace {
    indices: Vec<i64>,
}

impl PlyFace {
    fn set_list<T: Into<i64>>(&mut self, name: &str, values: Vec<T>) -> PropertyAccessResult {
        if !is_index_list(name) {
            return PropertyAccessResult::Ignored;
        }
        self.indices = values.into_iter().map(Into::into).collect();
        PropertyAccessResult::Set
    }
}

fn is_index_list(name: &str) -> bool {
    name == "vertex_indices" || name == "vertex_index"
}

impl PropertyAccess for PlyFace {
    fn new() -> Self {
        PlyFace::default()
    }
    fn set_list_char(&mut self, name: &str, v: Vec<i8>) -> PropertyAccessResult {
        self.set_list(name, v)
    }
    fn set_list_uchar(&mut self, name: &str, v: Vec<u8>) -> PropertyAccessResult {
        self.set_list(name, v)
    }
    fn set_list_short(&mut self, name: &str, v: Vec<i16>) -> PropertyAccessResult {
        self.set_list(name, v)
    }
    fn set_list_ushort(&mut self, name: &str, v: Vec<u16>) -> PropertyAccessResult {
        self.set_list(name, v)
    }
    fn set_list_int(&mut self, name: &str, v: Vec<i32>) -> PropertyAccessResult {
        self.set_list(name, v)
    }
    fn set_list_uint(&mut self, name: &str, v: Vec<u32>) -> PropertyAccessResult {
        self.set_list(name, v)
    }
}

/// Faces are written from this borrowed form, to avoid copying every triangle.
struct PlyTriangle([u32; 3]);

impl PropertyAccess for PlyTriangle {
    fn new() -> Self {
        PlyTriangle([0; 3])
    }
    fn get_list_uint(&self, name: &str) -> Option<&[u32]> {
        is_index_list(name).then_some(&self.0[..])
    }
}

/// Elements the pipeline does not use (normals-only elements, materials, edges...).
struct Skipped;

impl PropertyAccess for Skipped {
    fn new() -> Self {
        Skipped
    }
    fn begin_list_uchar(&mut self, _: &str, _: usize) -> BeginList<'_, u8> {
        BeginList::UseSetter
    }
}

pub(super) fn read(bytes: &[u8]) -> Result<Mesh, ReadError> {
    let malformed = |e: ParseError| {
        if e.kind() == std::io::ErrorKind::UnexpectedEof {
            ReadError::Truncated(e.to_string())
        } else {
            ReadError::Malformed(e.to_string())
        }
    };
    let mut reader = Reader::new(bytes);
    let header = Parser::<PlyVertex>::new().read_header(&mut reader).map_err(malformed)?;
    let element_names: Vec<&str> = header.elements.values().map(|e| e.name.as_str()).collect();
    if !element_names.contains(&"vertex") || !element_names.contains(&"face") {
        return Err(ReadError::Malformed(format!(
            "expected vertex and face elements, found {element_names:?}"
        )));
    }
    if element_names.iter().position(|&n| n == "face")
        < element_names.iter().position(|&n| n == "vertex")
    {
        return Err(ReadError::Malformed("faces come before vertices".into()));
    }
    let payload = reader.into_inner();
    if let Some(mesh) = super::ply_binary::read(payload, &header) {
        return mesh;
    }
    let mut reader = Reader::new(payload);
    let mut vertices = Vec::new();
    let mut faces = Vec::new();
    for element in header.elements.values() {
        match element.name.as_str() {
            "vertex" => {
                vertices = Parser::<PlyVertex>::new()
                    .read_payload_for_element(&mut reader, element, &header)
                    .map_err(malformed)?;
            }
            "face" => {
                faces = Parser::<PlyFace>::new()
                    .read_payload_for_element(&mut reader, element, &header)
                    .map_err(malformed)?;
            }
            _ => {
                Parser::<Skipped>::new()
                    .read_payload_for_element(&mut reader, element, &header)
                    .map_err(malformed)?;
            }
        }
    }
    if let Some(i) = vertices.iter().position(|v| v.set != 0b111) {
        return Err(ReadError::Malformed(format!("vertex {i} lacks an x, y or z property")));
    }
    let mut triangles = Vec::with_capacity(faces.len());
    let mut polygon = Vec::new();
    for (face, f) in faces.iter().enumerate() {
        polygon.clear();
        for &index in &f.indices {
            match u32::try_from(index) {
                Ok(i) if (i as usize) < vertices.len() => polygon.push(i),
                _ => {
                    return Err(ReadError::IndexOutOfRange {
                        face,
                        index,
                        vertices: vertices.len(),
                    });
                }
            }
        }
        fan(&polygon, &mut triangles);
    }
    check_indices(&triangles, vertices.len())?;
    let positions = vertices.iter().map(|v| DVec3::from_array(v.position)).collect();
    Ok(Mesh::new(positions, triangles))
}

/// Binary little-endian PLY with `double` coordinates, so a write-read round trip is exact.
pub(super) fn encode(mesh: &Mesh) -> Vec<u8> {
    let mut header = Header::new();
    header.encoding = Encoding::BinaryLittleEndian;
    header.comments.push("written by dressform".into());
    let mut vertex = ElementDef::new("vertex".into());
    vertex.count = mesh.positions.len();
    for axis in ["x", "y", "z"] {
        vertex
            .properties
            .add(PropertyDef::new(axis.into(), PropertyType::Scalar(ScalarType::Double)));
    }
    let mut face = ElementDef::new("face".into());
    face.count = mesh.triangles.len();
    face.properties.add(PropertyDef::new(
        "vertex_indices".into(),
        PropertyType::List(ScalarType::UChar, ScalarType::UInt),
    ));
    header.elements.add(vertex.clone());
    header.elements.add(face.clone());

    let vertices: Vec<PlyVertex> =
        mesh.positions.iter().map(|p| PlyVertex { position: p.to_array(), set: 0b111 }).collect();
    let triangles: Vec<PlyTriangle> = mesh.triangles.iter().map(|&t| PlyTriangle(t)).collect();
    let mut out = Vec::with_capacity(256 + mesh.positions.len() * 24 + mesh.triangles.len() * 13);
    // Writing into a Vec cannot fail, and the element definitions match the structs above.
    let written = Writer::<PlyVertex>::new()
        .write_header(&mut out, &header)
        .and_then(|_| {
            Writer::<PlyVertex>::new()
                .write_payload_of_element(&mut out, &vertices, &vertex, &header)
        })
        .and_then(|_| {
            Writer::<PlyTriangle>::new()
                .write_payload_of_element(&mut out, &triangles, &face, &header)
        });
    debug_assert!(written.is_ok(), "PLY encoding into memory failed: {written:?}");
    out
}
