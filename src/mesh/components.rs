//! Connected components: triangles connected through shared vertices.

use super::{Aabb, Mesh};

/// One connected piece of a mesh.
#[derive(Debug, Clone)]
pub struct Component {
    /// Indices of its triangles in the mesh.
    pub triangles: Vec<usize>,
    /// Its surface area.
    pub area: f64,
    /// Its bounding box.
    pub bounds: Aabb,
}

/// The connected components of `mesh`, largest area first.
pub fn components(mesh: &Mesh) -> Vec<Component> {
    let mut sets = DisjointSets::new(mesh.positions.len());
    for &[a, b, c] in &mesh.triangles {
        sets.union(a as usize, b as usize);
        sets.union(a as usize, c as usize);
    }
    let mut index_of_root = vec![usize::MAX; mesh.positions.len()];
    let mut groups: Vec<Vec<usize>> = Vec::new();
    for (t, tri) in mesh.triangles.iter().enumerate() {
        let root = sets.find(tri[0] as usize);
        if index_of_root[root] == usize::MAX {
            index_of_root[root] = groups.len();
            groups.push(Vec::new());
        }
        groups[index_of_root[root]].push(t);
    }
    let mut out: Vec<Component> = groups
        .into_iter()
        .map(|triangles| {
            let area = triangles.iter().map(|&t| mesh.triangle_area(t)).sum();
            let corners = triangles.iter().flat_map(|&t| mesh.corners(t));
            let bounds = Aabb::around(corners).expect("a component has triangles");
            Component { triangles, area, bounds }
        })
        .collect();
    out.sort_by(|a, b| b.area.total_cmp(&a.area));
    out
}

/// Union-find with path halving and union by size.
pub(super) struct DisjointSets {
    parent: Vec<usize>,
    size: Vec<usize>,
}

impl DisjointSets {
    pub(super) fn new(n: usize) -> Self {
        DisjointSets { parent: (0..n).collect(), size: vec![1; n] }
    }

    pub(super) fn find(&mut self, mut x: usize) -> usize {
        while self.parent[x] != x {
            self.parent[x] = self.parent[self.parent[x]];
            x = self.parent[x];
        }
        x
    }

    pub(super) fn union(&mut self, a: usize, b: usize) {
        let (mut a, mut b) = (self.find(a), self.find(b));
        if a == b {
            return;
        }
        if self.size[a] < self.size[b] {
            std::mem::swap(&mut a, &mut b);
        }
        self.parent[b] = a;
        self.size[a] += self.size[b];
    }
}
