//! Wavefront OBJ: `v` positions and `f` faces (any polygon, fanned into triangles; indices
//! 1-based or negative, with or without `/texture/normal` parts). Other statements (normals,
//! texture coordinates, groups, materials, lines, points) are not needed by the pipeline and
//! are skipped. One vertex numbering for the whole file, whatever its groups.

use super::text::{integer, lines, number, shown, words};
use super::{MeshFile, ReadError, fan};
use crate::body::mesh::Mesh;
use glam::DVec3;
use std::fmt::Write as _;

pub(super) fn read(bytes: &[u8]) -> Result<MeshFile, ReadError> {
    let mut file = MeshFile::default();
    let mut header = true;
    let mut polygon: Vec<u32> = Vec::new();
    // Faces may name vertices defined further down; those are checked at the end.
    let mut ahead: Vec<(usize, u32)> = Vec::new();
    for (line, text) in lines(bytes) {
        let (statement, comment) = match text.iter().position(|&b| b == b'#') {
            Some(at) => (&text[..at], Some(&text[at + 1..])),
            None => (text, None),
        };
        let mut w = words(statement);
        let Some(keyword) = w.next() else {
            if let (true, Some(c)) = (header, comment) {
                let c = c.strip_prefix(b" ").unwrap_or(c);
                file.comments.push(String::from_utf8_lossy(c).trim_end().to_string());
            }
            continue;
        };
        header = false;
        match keyword {
            b"v" => {
                let mut p = [0.0; 3];
                for (k, c) in p.iter_mut().enumerate() {
                    let word = w.next().ok_or_else(|| {
                        ReadError::at(line, format!("a vertex needs 3 coordinates, found {k}"))
                    })?;
                    *c = number(word, line)?;
                }
                file.mesh.positions.push(DVec3::from_array(p));
            }
            b"f" => {
                polygon.clear();
                for word in w {
                    let index = vertex_index(word, line, file.mesh.positions.len())?;
                    if index as usize >= file.mesh.positions.len() {
                        ahead.push((line, index));
                    }
                    polygon.push(index);
                }
                if polygon.len() < 3 {
                    let n = polygon.len();
                    return Err(ReadError::at(line, format!("a face needs 3 vertices, found {n}")));
                }
                fan(&polygon, &mut file.mesh.triangles);
            }
            _ => {}
        }
    }
    let vertices = file.mesh.positions.len();
    if let Some(&(line, index)) = ahead.iter().find(|&&(_, i)| i as usize >= vertices) {
        return Err(ReadError::at(
            line,
            format!("the face refers to vertex {}, but the file has {vertices}", index + 1),
        ));
    }
    Ok(file)
}

/// The 0-based vertex of a face word (`7`, `7/2`, `7//3`, `-1/2/3`); `defined` vertices come
/// before this line (negative indices count back from there).
fn vertex_index(word: &[u8], line: usize, defined: usize) -> Result<u32, ReadError> {
    let first = word.split(|&b| b == b'/').next().unwrap_or(word);
    let n = integer(first, line)?;
    let index = match n {
        1.. => Some(n - 1),
        0 => None,
        _ => (defined as i64).checked_add(n).filter(|&i| i >= 0),
    };
    index.and_then(|i| u32::try_from(i).ok()).ok_or_else(|| {
        let problem = if n > 0 {
            format!("vertex {n} is beyond the 4-billion-vertex limit")
        } else {
            format!("vertex index {} names no vertex (OBJ counts from 1)", shown(first))
        };
        ReadError::at(line, problem)
    })
}

/// ASCII OBJ: `comments` as `#` lines, then positions as Rust prints them (the shortest
/// decimal that reads back to the same `f64`), then triangles.
pub(super) fn encode(mesh: &Mesh, comments: &[String]) -> Vec<u8> {
    let mut s = String::with_capacity(mesh.positions.len() * 32 + mesh.triangles.len() * 24);
    for c in comments {
        let _ = writeln!(s, "# {}", super::one_line(c));
    }
    for p in &mesh.positions {
        let _ = writeln!(s, "v {} {} {}", p.x, p.y, p.z);
    }
    for t in &mesh.triangles {
        let _ = writeln!(s, "f {} {} {}", t[0] + 1, t[1] + 1, t[2] + 1);
    }
    s.into_bytes()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn header_comments_indices_and_polygons() {
        let text = "# units: mm\n#up: +z\n\n# third\nv 0 0 0\n# not header\nv 1 0 0 1\n\
                    v 1 1 0\r\nv 0 1 0 0.5 0.5 0.5\ng part\nf 1/1 2//2 -2/3/3 -1\nf 1 2 3 # done\n";
        let file = read(text.as_bytes()).unwrap();
        assert_eq!(file.comments, ["units: mm", "up: +z", "third"]);
        assert_eq!(file.mesh.positions.len(), 4);
        assert_eq!(file.mesh.triangles, [[0, 1, 2], [0, 2, 3], [0, 1, 2]]);
    }

    #[test]
    fn faces_may_name_vertices_defined_later() {
        let file = read(b"f 1 2 3\nv 0 0 0\nv 1 0 0\nv 0 1 0\n").unwrap();
        assert_eq!(file.mesh.triangles, [[0, 1, 2]]);
        let e = read(b"f 1 2 4\nv 0 0 0\nv 1 0 0\nv 0 1 0\n").unwrap_err();
        assert_eq!(e.to_string(), "line 1: the face refers to vertex 4, but the file has 3");
    }

    #[test]
    fn problems_name_the_line() {
        let cases: [(&[u8], &str); 5] = [
            (b"v 1 2 three\n", "line 1: 'three' is not a number"),
            (b"v 0 0 0\nv 1 2\n", "line 2: a vertex needs 3 coordinates, found 2"),
            (b"v 0 0 0\nf 0 1 1\n", "line 2: vertex index '0' names no vertex"),
            (b"v 0 0 0\nf -2 1 1\n", "line 2: vertex index '-2' names no vertex"),
            (b"v 0 0 0\nf 1 1\n", "line 2: a face needs 3 vertices, found 2"),
        ];
        for (bytes, expected) in cases {
            let e = read(bytes).unwrap_err().to_string();
            assert!(e.starts_with(expected), "{e}");
        }
    }
}
