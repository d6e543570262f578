//! Connected components: triangles connected through shared vertices.

use super::{Aabb, Mesh};
use glam::DVec3;
use rayon::prelude::*;

/// One connected piece of a mesh.
#[derive(Debug, Clone, PartialEq)]
pub struct Component {
    /// How many triangles it has.
    pub triangles: usize,
    /// Its surface area.
    pub area: f64,
    /// Its bounding box.
    pub bounds: Aabb,
}

/// The connected components of a mesh.
#[derive(Debug, Clone)]
pub struct Components {
    /// The pieces, largest area first.
    pub parts: Vec<Component>,
    /// For each triangle, the index of its piece in `parts`.
    pub of_triangle: Vec<u32>,
}

/// The connected components of `mesh`: a union-find over vertices, then one parallel pass for
/// the pieces' triangle counts, areas and boxes.
pub fn components(mesh: &Mesh) -> Components {
    let mut sets = DisjointSets::new(mesh.positions.len());
    for &[a, b, c] in &mesh.triangles {
        sets.union(a as usize, b as usize);
        sets.union(a as usize, c as usize);
    }
    // Number the pieces in order of first appearance, one id per vertex.
    let mut id_of_root = vec![u32::MAX; mesh.positions.len()];
    let mut count = 0u32;
    let id_of_vertex: Vec<u32> = (0..mesh.positions.len())
        .map(|v| {
            let root = sets.find(v);
            if id_of_root[root] == u32::MAX {
                id_of_root[root] = count;
                count += 1;
            }
            id_of_root[root]
        })
        .collect();
    let of_triangle: Vec<u32> =
        mesh.triangles.par_iter().map(|tri| id_of_vertex[tri[0] as usize]).collect();
    let empty = || {
        vec![
            Component {
                triangles: 0,
                area: 0.0,
                bounds: Aabb { min: DVec3::INFINITY, max: DVec3::NEG_INFINITY }
            };
            count as usize
        ]
    };
    let parts = (0..mesh.triangles.len())
        .into_par_iter()
        .fold(empty, |mut parts, t| {
            let part = &mut parts[of_triangle[t] as usize];
            let [a, b, c] = mesh.corners(t);
            part.triangles += 1;
            part.area += 0.5 * (b - a).cross(c - a).length();
            part.bounds.min = part.bounds.min.min(a).min(b).min(c);
            part.bounds.max = part.bounds.max.max(a).max(b).max(c);
            parts
        })
        .reduce(empty, |mut x, y| {
            for (p, q) in x.iter_mut().zip(y) {
                p.triangles += q.triangles;
                p.area += q.area;
                p.bounds.min = p.bounds.min.min(q.bounds.min);
                p.bounds.max = p.bounds.max.max(q.bounds.max);
            }
            x
        });
    // Largest area first.
    let mut order: Vec<usize> = (0..parts.len()).collect();
    order.sort_by(|&a, &b| parts[b].area.total_cmp(&parts[a].area));
    let mut rank = vec![0u32; parts.len()];
    for (r, &id) in order.iter().enumerate() {
        rank[id] = r as u32;
    }
    let of_triangle = of_triangle.into_par_iter().map(|id| rank[id as usize]).collect();
    let parts = order.into_iter().map(|id| parts[id].clone()).collect();
    Components { parts, of_triangle }
}

/// Union-find with path halving and union by size.
struct DisjointSets {
    parent: Vec<u32>,
    size: Vec<u32>,
}

impl DisjointSets {
    fn new(n: usize) -> Self {
        DisjointSets { parent: (0..n as u32).collect(), size: vec![1; n] }
    }

    fn find(&mut self, mut x: usize) -> usize {
        while self.parent[x] as usize != x {
            self.parent[x] = self.parent[self.parent[x] as usize];
            x = self.parent[x] as usize;
        }
        x
    }

    fn union(&mut self, a: usize, b: usize) {
        let (mut a, mut b) = (self.find(a), self.find(b));
        if a == b {
            return;
        }
        if self.size[a] < self.size[b] {
            std::mem::swap(&mut a, &mut b);
        }
        self.parent[b] = a as u32;
        self.size[a] += self.size[b];
    }
}
