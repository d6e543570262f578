//! The one triangle-mesh type of the pipeline, and queries on it.
//!
//! A [`Mesh`] is an indexed triangle list in `f64`. Readers produce it, the canonical frame
//! moves it, slicing and symmetry read it, writers store it.

mod adjacency;
mod components;
pub mod decimate;
mod grow;
pub mod reduce;
pub mod smooth;
mod topology;
mod weld;

pub use components::{Component, Components, NO_PIECE, components};
pub use grow::grow;
pub use topology::{Topology, topology};

use glam::DVec3;
use rayon::prelude::*;
use rustc_hash::FxHashMap;

/// An indexed triangle mesh. Triangles are counter-clockwise seen from outside.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Mesh {
    /// Vertex positions.
    pub positions: Vec<DVec3>,
    /// Triangles as indices into `positions`.
    pub triangles: Vec<[u32; 3]>,
}

/// An axis-aligned bounding box.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Aabb {
    /// Smallest coordinate on each axis.
    pub min: DVec3,
    /// Largest coordinate on each axis.
    pub max: DVec3,
}

impl Aabb {
    /// The box around `points`, or `None` when there are none.
    pub fn around(points: impl IntoIterator<Item = DVec3>) -> Option<Self> {
        let mut it = points.into_iter();
        let first = it.next()?;
        Some(it.fold(Aabb { min: first, max: first }, |b, p| Aabb {
            min: b.min.min(p),
            max: b.max.max(p),
        }))
    }

    /// Edge lengths of the box.
    pub fn size(&self) -> DVec3 {
        self.max - self.min
    }
}

/// A triangle naming a vertex the mesh does not have ([`Mesh::try_new`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[error("face {triangle} refers to vertex {index}, but there are only {vertices} vertices")]
pub struct BadIndex {
    /// The triangle (0-based).
    pub triangle: usize,
    /// The index it names.
    pub index: u32,
    /// How many vertices there are.
    pub vertices: usize,
}

impl Mesh {
    /// A mesh from positions and triangles whose indices are known to be in range (built by
    /// code, not read from a file: files go through [`Mesh::try_new`]).
    pub fn new(positions: Vec<DVec3>, triangles: Vec<[u32; 3]>) -> Self {
        Mesh { positions, triangles }
    }

    /// A mesh from positions and triangles, if every index names a vertex; else the first
    /// triangle that does not. The readers' boundary: every decoded file passes here.
    pub fn try_new(positions: Vec<DVec3>, triangles: Vec<[u32; 3]>) -> Result<Self, BadIndex> {
        let vertices = positions.len();
        let bad = triangles.par_iter().enumerate().find_map_first(|(triangle, t)| {
            let index = *t.iter().find(|&&i| i as usize >= vertices)?;
            Some(BadIndex { triangle, index, vertices })
        });
        match bad {
            Some(bad) => Err(bad),
            None => Ok(Mesh { positions, triangles }),
        }
    }

    /// The three corners of triangle `t`.
    pub fn corners(&self, t: usize) -> [DVec3; 3] {
        self.triangles[t].map(|i| self.positions[i as usize])
    }

    /// Area-weighted normal of triangle `t` (length = twice the area).
    pub fn scaled_normal(&self, t: usize) -> DVec3 {
        let [a, b, c] = self.corners(t);
        (b - a).cross(c - a)
    }

    /// Area of triangle `t`.
    pub fn triangle_area(&self, t: usize) -> f64 {
        0.5 * self.scaled_normal(t).length()
    }

    /// Total surface area.
    pub fn area(&self) -> f64 {
        (0..self.triangles.len()).map(|t| self.triangle_area(t)).sum()
    }

    /// Bounding box of the vertices, or `None` for a mesh without triangles. (Unused vertices
    /// count too; meshes from [`crate::body::scan`] have none.)
    pub fn bounds(&self) -> Option<Aabb> {
        if self.triangles.is_empty() {
            return None;
        }
        self.positions
            .par_chunks(1 << 14)
            .filter_map(|block| Aabb::around(block.iter().copied()))
            .reduce_with(|a, b| Aabb { min: a.min.min(b.min), max: a.max.max(b.max) })
    }

    /// Signed volume enclosed (positive for a closed, outward-oriented mesh).
    pub fn signed_volume(&self) -> f64 {
        (0..self.triangles.len())
            .map(|t| {
                let [a, b, c] = self.corners(t);
                a.dot(b.cross(c)) / 6.0
            })
            .sum()
    }

    /// The same mesh with every position mapped by `f`.
    pub fn map_positions(&self, f: impl Fn(DVec3) -> DVec3) -> Mesh {
        Mesh {
            positions: self.positions.iter().map(|&p| f(p)).collect(),
            triangles: self.triangles.clone(),
        }
    }

    /// Maps every position by `f` in place.
    pub fn transform(&mut self, f: impl Fn(DVec3) -> DVec3 + Sync) {
        self.positions.par_iter_mut().for_each(|p| *p = f(*p));
    }

    /// Keeps only the triangles for which `keep` is true, then drops unused vertices.
    pub fn retain_triangles(&mut self, mut keep: impl FnMut(usize) -> bool) {
        let mut t = 0;
        self.triangles.retain(|_| {
            t += 1;
            keep(t - 1)
        });
        self.drop_unused_vertices();
    }

    /// The part of the mesh made of the triangles for which `keep` is true, with only the
    /// vertices they use (in order of first use).
    pub fn part(&self, keep: impl Fn([u32; 3]) -> bool + Sync) -> Mesh {
        self.part_of(self.triangles.par_iter().copied().filter(|&tri| keep(tri)).collect())
    }

    /// The part of the mesh made of `triangles` (some of its own), with only the vertices they
    /// use (in order of first use).
    pub fn part_of(&self, mut triangles: Vec<[u32; 3]>) -> Mesh {
        let mut index: FxHashMap<u32, u32> = FxHashMap::default();
        let mut positions = Vec::new();
        for v in triangles.iter_mut().flatten() {
            *v = *index.entry(*v).or_insert_with(|| {
                positions.push(self.positions[*v as usize]);
                positions.len() as u32 - 1
            });
        }
        Mesh { positions, triangles }
    }

    /// Removes vertices no triangle refers to, keeping the others in their order.
    pub fn drop_unused_vertices(&mut self) {
        // One bit per vertex, set in parallel over blocks of triangles, then merged.
        let words = self.positions.len().div_ceil(64);
        let used = self
            .triangles
            .par_chunks(1 << 16)
            .fold(
                || vec![0u64; words],
                |mut used, block| {
                    for &i in block.iter().flatten() {
                        used[i as usize / 64] |= 1 << (i % 64);
                    }
                    used
                },
            )
            .reduce(
                || vec![0u64; words],
                |mut a, b| {
                    a.iter_mut().zip(b).for_each(|(x, y)| *x |= y);
                    a
                },
            );
        let is_used = |i: usize| used[i / 64] & (1 << (i % 64)) != 0;
        if (0..self.positions.len()).all(is_used) {
            return;
        }
        let mut new_index = vec![u32::MAX; self.positions.len()];
        let mut next = 0;
        for i in (0..self.positions.len()).filter(|&i| is_used(i)) {
            new_index[i] = next;
            self.positions[next as usize] = self.positions[i];
            next += 1;
        }
        self.positions.truncate(next as usize);
        self.triangles.par_iter_mut().for_each(|tri| *tri = tri.map(|i| new_index[i as usize]));
    }

    /// Merges vertices with bit-identical positions; returns how many were merged away.
    pub fn weld_identical(&mut self) -> usize {
        weld::weld_identical(self)
    }
}

/// Small meshes for unit tests.
#[cfg(test)]
pub(crate) mod shapes {
    use super::Mesh;
    use glam::DVec3;

    /// Appends an outward tetrahedron with its right-angled corner at `at` and legs `s` long.
    pub fn add_tetrahedron(mesh: &mut Mesh, at: DVec3, s: f64) {
        let first = mesh.positions.len() as u32;
        mesh.positions.extend([at, at + DVec3::X * s, at + DVec3::Y * s, at + DVec3::Z * s]);
        let [a, b, c, d] = [first, first + 1, first + 2, first + 3];
        mesh.triangles.extend([[a, c, b], [a, b, d], [a, d, c], [b, c, d]]);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn try_new_refuses_an_index_past_the_vertices() {
        let three = vec![DVec3::ZERO, DVec3::X, DVec3::Y];
        assert!(Mesh::try_new(three.clone(), vec![[0, 1, 2]]).is_ok());
        let bad = Mesh::try_new(three, vec![[0, 1, 2], [2, 3, 0]]).unwrap_err();
        assert_eq!(bad, BadIndex { triangle: 1, index: 3, vertices: 3 });
        assert_eq!(bad.to_string(), "face 1 refers to vertex 3, but there are only 3 vertices");
    }
}
