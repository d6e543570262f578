//! Stanford PLY, ASCII and binary of either endianness: the `vertex` element's `x`, `y`, `z`
//! (any numeric type) and the `face` element's `vertex_indices` (or `vertex_index`) list,
//! polygons fanned into triangles; other elements and properties are read past. The header's
//! `comment` lines are returned.
//!
//! The header is checked against the file's size before anything is allocated (see
//! [`header::parse`]); binary elements whose items have one size are decoded in parallel
//! ([`records`]), anything else one number at a time ([`values::walk`]).

mod header;
mod records;
mod values;

use super::{MeshFile, ReadError};
use crate::body::mesh::Mesh;
use header::{Element, Encoding, Header, Kind};
use values::{Bytes, Found, Role, Text, unusable, walk};

pub(super) fn read(bytes: &[u8]) -> Result<MeshFile, ReadError> {
    let (header, payload) = header::parse(bytes)?;
    let roles = roles(&header)?;
    let mut found = Found::default();
    match header.encoding {
        Encoding::Binary { big_endian } => {
            let mut bytes = Bytes { bytes: payload, at: 0, big_endian };
            for (element, role) in header.elements.iter().zip(roles) {
                read_binary(&mut bytes, element, role, &mut found)?;
            }
        }
        Encoding::Ascii => {
            let header_lines = bytes.len() - payload.len();
            let first_line = super::text::lines(&bytes[..header_lines]).count();
            let words = super::text::Words::new(payload);
            let mut text = Text { words, first_line };
            for (element, role) in header.elements.iter().zip(roles) {
                let role = role.with_vertices(found.positions.len());
                walk(&mut text, element, &role, &mut found)?;
            }
        }
    }
    let mesh = Mesh::new(found.positions, found.triangles);
    Ok(MeshFile { mesh, comments: header.comments })
}

fn read_binary(
    bytes: &mut Bytes,
    element: &Element,
    role: Role,
    found: &mut Found,
) -> Result<(), ReadError> {
    let role = role.with_vertices(found.positions.len());
    let fast = match role {
        Role::Vertex(xyz) => records::vertices(bytes, element, xyz)
            .map(|r| r.map(|positions| found.positions = positions)),
        Role::Face { list, vertices } => records::triangles(bytes, element, list, vertices)
            .map(|r| r.map(|triangles| found.triangles = triangles)),
        Role::Other => records::skip(bytes, element),
    };
    fast.unwrap_or_else(|| walk(bytes, element, &role, found))
}

impl Role {
    /// The role with the vertex count known so far (faces check their indices against it).
    fn with_vertices(self, count: usize) -> Role {
        match self {
            Role::Face { list, .. } => Role::Face { list, vertices: count },
            role => role,
        }
    }
}

/// What each element is to the mesh: the first `vertex` element gives the positions, the
/// first `face` element after it the triangles.
fn roles(header: &Header) -> Result<Vec<Role>, ReadError> {
    let position = |name: &str| header.elements.iter().position(|e| e.name == name);
    let (Some(v), Some(f)) = (position("vertex"), position("face")) else {
        let names = header.elements.iter().map(Element::shown);
        return Err(ReadError::Malformed(format!(
            "expected vertex and face elements, found {}",
            if header.elements.is_empty() { "none".into() } else { crate::messages::list(names) }
        )));
    };
    if f < v {
        return Err(ReadError::Malformed("faces come before vertices".into()));
    }
    let vertex = &header.elements[v];
    if vertex.count > u32::MAX as usize {
        return Err(unusable(vertex, "has more than 4 billion vertices"));
    }
    let axis = |name| match vertex.property(name) {
        Some(k) if matches!(vertex.properties[k].kind, Kind::Scalar(_)) => Some(k),
        _ => None,
    };
    let (Some(x), Some(y), Some(z)) = (axis("x"), axis("y"), axis("z")) else {
        return Err(unusable(vertex, "lacks an x, y or z number"));
    };
    let face = &header.elements[f];
    let list = face.property("vertex_indices").or_else(|| face.property("vertex_index"));
    let list = match list.map(|k| (k, face.properties[k].kind)) {
        Some((k, Kind::List { item, .. })) if item.is_integer() => k,
        _ => return Err(unusable(face, "has no vertex_indices list of integers")),
    };
    Ok((0..header.elements.len())
        .map(|k| match k {
            _ if k == v => Role::Vertex([x, y, z]),
            _ if k == f => Role::Face { list, vertices: 0 },
            _ => Role::Other,
        })
        .collect())
}

/// Binary little-endian PLY with `double` coordinates (a write-read round trip is exact) and
/// `comments` as `comment` lines.
pub(super) fn encode(mesh: &Mesh, comments: &[String]) -> Vec<u8> {
    let mut out = Vec::with_capacity(256 + mesh.positions.len() * 24 + mesh.triangles.len() * 13);
    out.extend_from_slice(b"ply\nformat binary_little_endian 1.0\n");
    for c in comments {
        out.extend_from_slice(format!("comment {}\n", super::one_line(c)).as_bytes());
    }
    out.extend_from_slice(
        format!(
            "element vertex {}\nproperty double x\nproperty double y\nproperty double z\n\
             element face {}\nproperty list uchar uint vertex_indices\nend_header\n",
            mesh.positions.len(),
            mesh.triangles.len()
        )
        .as_bytes(),
    );
    for p in &mesh.positions {
        for c in p.to_array() {
            out.extend_from_slice(&c.to_le_bytes());
        }
    }
    for t in &mesh.triangles {
        out.push(3);
        for i in t {
            out.extend_from_slice(&i.to_le_bytes());
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ascii(body: &str) -> Vec<u8> {
        format!(
            "ply\nformat ascii 1.0\ncomment units: mm\nelement vertex 3\nproperty float x\n\
             property float y\nproperty float z\nelement face 1\n\
             property list uchar int vertex_indices\nend_header\n{body}"
        )
        .into_bytes()
    }

    #[test]
    fn ascii_problems_name_the_file_line() {
        let e = read(&ascii("0 0 0\n1 0 0\n0 x 0\n3 0 1 2\n")).unwrap_err();
        assert_eq!(e.to_string(), "line 13: 'x' is not a number");
        let e = read(&ascii("0 0 0\n1 0 0\n0 1 0\n3 0 1\n")).unwrap_err();
        assert_eq!(e.to_string(), "truncated: the data ends in item 0 of the 1 'face' element");
        let e = read(&ascii("0 0 0\n1 0 0\n0 1 0\n-1 0 1\n")).unwrap_err();
        assert!(e.to_string().contains("list 'vertex_indices' has -1 entries"), "{e}");
    }

    #[test]
    fn round_trip_with_comments() {
        let file = read(&ascii("0 0 0\n1 0 0\n0 1 0\n4 0 1 2 0\n")).unwrap();
        assert_eq!(file.comments, ["units: mm"]);
        assert_eq!(file.mesh.triangles, [[0, 1, 2], [0, 2, 0]]);
        let again = read(&encode(&file.mesh, &["a\nb".into(), "up: +z".into()])).unwrap();
        assert_eq!(again.mesh, file.mesh);
        assert_eq!(again.comments, ["a b", "up: +z"]);
    }
}
