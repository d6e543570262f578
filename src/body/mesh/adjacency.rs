//! Vertex-to-triangle incidence in compressed (CSR) form, built by
//! counting sort in linear time: the basis of the topology queries on million-triangle scans.

use super::Mesh;

/// For each vertex, a list of items (triangles or half-edges), stored contiguously.
pub(super) struct Incidence {
    offsets: Vec<u32>,
    items: Vec<u32>,
}

impl Incidence {
    /// The items of vertex `v`.
    pub(super) fn of(&self, v: usize) -> &[u32] {
        &self.items[self.offsets[v] as usize..self.offsets[v + 1] as usize]
    }

    /// The triangles around each vertex, each vertex's in increasing order (a triangle with
    /// a repeated corner is listed once per corner).
    pub(super) fn triangles(mesh: &Mesh) -> Self {
        let mut offsets = vec![0u32; mesh.positions.len() + 1];
        for tri in &mesh.triangles {
            for &v in tri {
                offsets[v as usize + 1] += 1;
            }
        }
        for v in 0..mesh.positions.len() {
            offsets[v + 1] += offsets[v];
        }
        let mut cursor = offsets.clone();
        let mut items = vec![0u32; mesh.triangles.len() * 3];
        for (t, tri) in mesh.triangles.iter().enumerate() {
            for &v in tri {
                let slot = &mut cursor[v as usize];
                items[*slot as usize] = t as u32;
                *slot += 1;
            }
        }
        Incidence { offsets, items }
    }
}
