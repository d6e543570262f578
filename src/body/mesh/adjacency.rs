//! Vertex-to-triangle and vertex-to-half-edge incidence in compressed (CSR) form, built by
//! counting sort in linear time: the basis of the topology queries on million-triangle scans.

use super::Mesh;

/// For each vertex, a list of items (triangles or half-edges), stored contiguously.
pub(super) struct Incidence {
    offsets: Vec<u32>,
    items: Vec<u32>,
}

impl Incidence {
    /// Groups `items` (given as `(vertex, item)` pairs, `count` of them) by vertex.
    fn build(vertices: usize, count: usize, pairs: impl Fn(&mut dyn FnMut(u32, u32))) -> Self {
        let mut offsets = vec![0u32; vertices + 1];
        pairs(&mut |v, _| offsets[v as usize + 1] += 1);
        for v in 0..vertices {
            offsets[v + 1] += offsets[v];
        }
        let mut cursor = offsets.clone();
        let mut items = vec![0u32; count];
        pairs(&mut |v, item| {
            let slot = &mut cursor[v as usize];
            items[*slot as usize] = item;
            *slot += 1;
        });
        Incidence { offsets, items }
    }

    /// The items of vertex `v`.
    pub(super) fn of(&self, v: usize) -> &[u32] {
        &self.items[self.offsets[v] as usize..self.offsets[v + 1] as usize]
    }

    /// The triangles around each vertex.
    pub(super) fn triangles(mesh: &Mesh) -> Self {
        Incidence::build(mesh.positions.len(), mesh.triangles.len() * 3, |emit| {
            for (t, tri) in mesh.triangles.iter().enumerate() {
                for &v in tri {
                    emit(v, t as u32);
                }
            }
        })
    }

    /// The half-edges (`3 t + k`, from corner `k` to `k + 1` of triangle `t`) filed under the
    /// lower-numbered of their two vertices.
    pub(super) fn half_edges_by_lower_vertex(mesh: &Mesh) -> Self {
        Incidence::build(mesh.positions.len(), mesh.triangles.len() * 3, |emit| {
            for (t, tri) in mesh.triangles.iter().enumerate() {
                for k in 0..3 {
                    emit(tri[k].min(tri[(k + 1) % 3]), (3 * t + k) as u32);
                }
            }
        })
    }
}
