//! `base.obj`, MakeHuman's base mesh "hm08": the full vertex list (skin, helper geometry and the
//! small cubes that locate joints; targets and weights index into all of it) and its groups.
//! Only the group `body` is skin: closed, genus 0, all quads, mirror-symmetric in x.

use super::{MakeHumanError, read_text, to_canonical};
use crate::body::mesh::Mesh;
use glam::DVec3;
use std::path::Path;

/// The name of the skin group in `base.obj`.
pub const SKIN_GROUP: &str = "body";

/// A named group of faces (`g name` in the OBJ file).
#[derive(Debug, Clone, PartialEq)]
pub struct Group {
    /// The group's name.
    pub name: String,
    /// Its faces, as 0-based indices into [`BaseMesh::vertices`].
    pub faces: Vec<Vec<u32>>,
}

/// The base mesh in the canonical frame (mm, Z up, facing -Y).
#[derive(Debug, Clone, PartialEq)]
pub struct BaseMesh {
    /// Every vertex of the file, in order.
    pub vertices: Vec<DVec3>,
    /// The groups, in file order.
    pub groups: Vec<Group>,
    /// The skin's quads (group `body`), counter-clockwise seen from outside.
    pub skin_quads: Vec<[u32; 4]>,
    /// The vertices the skin uses, ascending (hm08: 0..13380).
    pub skin_vertices: Vec<u32>,
}

impl BaseMesh {
    /// Reads `file`; an unreadable number, an out-of-range index or a skin that is not all
    /// quads is an error naming the file and line.
    pub fn load(file: &Path) -> Result<Self, MakeHumanError> {
        let text = read_text(file)?;
        let bad =
            |line: usize, what: &str| MakeHumanError::new(file, format!("line {line}: {what}"));
        let mut vertices = Vec::new();
        let mut groups: Vec<Group> = Vec::new();
        for (n, line) in text.lines().enumerate() {
            let mut words = line.split_whitespace();
            match words.next() {
                Some("v") => {
                    let c: Vec<f64> = words.take(3).filter_map(|w| w.parse().ok()).collect();
                    match c[..] {
                        [x, y, z] if c.iter().all(|v| v.is_finite()) => {
                            vertices.push(to_canonical(x, y, z))
                        }
                        _ => return Err(bad(n + 1, "a vertex needs three finite numbers")),
                    }
                }
                Some("g") => groups.push(Group {
                    name: words.next().unwrap_or_default().to_string(),
                    faces: Vec::new(),
                }),
                Some("f") => {
                    let face = words
                        .map(|w| match w.split('/').next().and_then(|i| i.parse::<u32>().ok()) {
                            Some(i) if i >= 1 => Ok(i - 1),
                            _ => Err(bad(n + 1, "a face index must be a positive integer")),
                        })
                        .collect::<Result<Vec<u32>, _>>()?;
                    if groups.is_empty() {
                        groups.push(Group { name: String::new(), faces: Vec::new() });
                    }
                    if let Some(group) = groups.last_mut() {
                        group.faces.push(face);
                    }
                }
                _ => {}
            }
        }
        let count = vertices.len();
        if let Some(g) =
            groups.iter().find(|g| g.faces.iter().flatten().any(|&i| i as usize >= count))
        {
            return Err(MakeHumanError::new(
                file,
                format!("group {}: a face refers to a vertex beyond the {count} vertices", g.name),
            ));
        }
        let skin = groups.iter().find(|g| g.name == SKIN_GROUP).ok_or_else(|| {
            MakeHumanError::new(file, format!("no group `{SKIN_GROUP}` (the skin)"))
        })?;
        let skin_quads = skin
            .faces
            .iter()
            .map(|f| <[u32; 4]>::try_from(f.as_slice()))
            .collect::<Result<Vec<_>, _>>()
            .map_err(|_| {
                MakeHumanError::new(
                    file,
                    format!("group `{SKIN_GROUP}` has a face that is not a quad"),
                )
            })?;
        let mut skin_vertices: Vec<u32> = skin_quads.iter().flatten().copied().collect();
        skin_vertices.sort_unstable();
        skin_vertices.dedup();
        Ok(BaseMesh { vertices, groups, skin_quads, skin_vertices })
    }

    /// The skin of a full vertex list (the base, shaped or posed) as a triangle mesh: the skin
    /// vertices in order (vertex `k` is `vertices[skin_vertices[k]]`), each quad split along its
    /// first diagonal.
    pub fn skin(&self, vertices: &[DVec3]) -> Mesh {
        let mut compact = vec![u32::MAX; vertices.len()];
        for (k, &v) in self.skin_vertices.iter().enumerate() {
            compact[v as usize] = k as u32;
        }
        let triangles = self
            .skin_quads
            .iter()
            .flat_map(|q| {
                let [a, b, c, d] = q.map(|v| compact[v as usize]);
                [[a, b, c], [a, c, d]]
            })
            .collect();
        Mesh::new(self.skin_vertices.iter().map(|&v| vertices[v as usize]).collect(), triangles)
    }
}
