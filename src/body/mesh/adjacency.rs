//! Vertex-to-triangle incidence in compressed (CSR) form, built by
//! counting sort in linear time: the basis of the topology queries on million-triangle scans.

use super::Mesh;

/// For each vertex, a list of items (one per triangle at it), stored contiguously.
pub(super) struct Incidence<T> {
    offsets: Vec<u32>,
    items: Vec<T>,
}

impl<T: Copy + Default> Incidence<T> {
    /// The items of vertex `v`.
    pub(super) fn of(&self, v: usize) -> &[T] {
        &self.items[self.offsets[v] as usize..self.offsets[v + 1] as usize]
    }

    /// For each corner `k` of each triangle `t` that `keep` accepts, `item(t, tri, k)` listed
    /// at the corner's vertex; each vertex's items in increasing triangle order.
    fn build(
        mesh: &Mesh,
        keep: impl Fn(&[u32; 3]) -> bool,
        item: impl Fn(u32, [u32; 3], usize) -> T,
    ) -> Self {
        let mut offsets = vec![0u32; mesh.positions.len() + 1];
        for tri in mesh.triangles.iter().filter(|tri| keep(tri)) {
            for &v in tri {
                offsets[v as usize + 1] += 1;
            }
        }
        for v in 0..mesh.positions.len() {
            offsets[v + 1] += offsets[v];
        }
        let mut cursor = offsets.clone();
        let mut items = vec![T::default(); offsets[mesh.positions.len()] as usize];
        for (t, &tri) in mesh.triangles.iter().enumerate() {
            if !keep(&tri) {
                continue;
            }
            for (k, &v) in tri.iter().enumerate() {
                let slot = &mut cursor[v as usize];
                items[*slot as usize] = item(t as u32, tri, k);
                *slot += 1;
            }
        }
        Incidence { offsets, items }
    }
}

impl Incidence<u32> {
    /// The triangles around each vertex, each vertex's in increasing order (a triangle with
    /// a repeated corner is listed once per corner).
    pub(super) fn triangles(mesh: &Mesh) -> Self {
        Self::build(mesh, |_| true, |t, _, _| t)
    }
}

impl Incidence<[u32; 2]> {
    /// The ring round each vertex: for each triangle at it (in increasing order), the
    /// triangle's next and previous corners, `[next, prev]`, so that the triangle runs
    /// `v -> next -> prev`. Triangles with a repeated corner are left out.
    pub(super) fn rings(mesh: &Mesh) -> Self {
        Self::build(
            mesh,
            |&[a, b, c]| a != b && b != c && a != c,
            |_, tri, k| [tri[(k + 1) % 3], tri[(k + 2) % 3]],
        )
    }
}
