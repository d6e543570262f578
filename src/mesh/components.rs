//! Connected components: triangles connected through shared vertices.

use super::{Aabb, Mesh};
use glam::DVec3;

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

/// The connected components of `mesh` (union-find over vertices, then one pass for the
/// pieces' areas and boxes).
pub fn components(mesh: &Mesh) -> Components {
    let mut sets = DisjointSets::new(mesh.positions.len());
    for &[a, b, c] in &mesh.triangles {
        sets.union(a as usize, b as usize);
        sets.union(a as usize, c as usize);
    }
    let mut id_of_root = vec![u32::MAX; mesh.positions.len()];
    let mut parts: Vec<Component> = Vec::new();
    let empty = Aabb { min: DVec3::INFINITY, max: DVec3::NEG_INFINITY };
    let mut of_triangle = Vec::with_capacity(mesh.triangles.len());
    for (t, tri) in mesh.triangles.iter().enumerate() {
        let root = sets.find(tri[0] as usize);
        if id_of_root[root] == u32::MAX {
            id_of_root[root] = parts.len() as u32;
            parts.push(Component { triangles: 0, area: 0.0, bounds: empty });
        }
        let id = id_of_root[root];
        of_triangle.push(id);
        let part = &mut parts[id as usize];
        let corners = mesh.corners(t);
        part.triangles += 1;
        part.area += 0.5 * (corners[1] - corners[0]).cross(corners[2] - corners[0]).length();
        for p in corners {
            part.bounds.min = part.bounds.min.min(p);
            part.bounds.max = part.bounds.max.max(p);
        }
    }
    let mut order: Vec<usize> = (0..parts.len()).collect();
    order.sort_by(|&a, &b| parts[b].area.total_cmp(&parts[a].area));
    let mut rank = vec![0u32; parts.len()];
    for (r, &id) in order.iter().enumerate() {
        rank[id] = r as u32;
    }
    for id in &mut of_triangle {
        *id = rank[*id as usize];
    }
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
