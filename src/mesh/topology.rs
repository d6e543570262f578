//! Edge topology: boundaries (holes), non-manifold edges and vertices, orientation.

use super::Mesh;
use super::components::DisjointSets;
use std::collections::HashMap;

/// What the edges of a mesh say about its surface.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Topology {
    /// Distinct undirected edges.
    pub edges: usize,
    /// Edges with exactly one triangle.
    pub boundary_edges: usize,
    /// Closed chains of boundary edges, as vertex indices in order: the holes.
    pub boundary_loops: Vec<Vec<u32>>,
    /// Edges shared by more than two triangles.
    pub non_manifold_edges: usize,
    /// Vertices whose triangles form more than one fan (e.g. two cones touching at a tip).
    pub non_manifold_vertices: usize,
    /// Two-triangle edges that both triangles run in the same direction (flipped neighbours).
    pub misoriented_edges: usize,
}

impl Topology {
    /// No boundary edges: a closed surface.
    pub fn is_closed(&self) -> bool {
        self.boundary_edges == 0
    }

    /// Every edge has at most two triangles and every vertex a single fan.
    pub fn is_manifold(&self) -> bool {
        self.non_manifold_edges == 0 && self.non_manifold_vertices == 0
    }

    /// Neighbouring triangles agree on orientation.
    pub fn is_consistently_oriented(&self) -> bool {
        self.misoriented_edges == 0
    }
}

/// Half-edge `k` of triangle `t` runs from corner `k` to corner `k + 1`.
fn half_edge(mesh: &Mesh, h: usize) -> (u32, u32) {
    let tri = mesh.triangles[h / 3];
    (tri[h % 3], tri[(h + 1) % 3])
}

/// Index of the corner of triangle `h / 3` that holds vertex `v`.
fn corner_of(mesh: &Mesh, h: usize, v: u32) -> usize {
    let t = h / 3;
    let k = mesh.triangles[t].iter().position(|&x| x == v).unwrap_or(0);
    3 * t + k
}

/// Analyses the edges of `mesh`. Sorting the half-edges by their undirected key keeps this
/// `O(n log n)` without a hash map per edge.
pub fn topology(mesh: &Mesh) -> Topology {
    let mut keyed: Vec<(u64, u32)> = (0..mesh.triangles.len() * 3)
        .map(|h| {
            let (a, b) = half_edge(mesh, h);
            let key = (u64::from(a.min(b)) << 32) | u64::from(a.max(b));
            (key, h as u32)
        })
        .collect();
    keyed.sort_unstable();

    let mut topo = Topology::default();
    let mut fans = DisjointSets::new(mesh.triangles.len() * 3);
    let mut boundary = Vec::new();
    for run in keyed.chunk_by(|x, y| x.0 == y.0) {
        topo.edges += 1;
        match run {
            [(_, h)] => {
                topo.boundary_edges += 1;
                boundary.push(half_edge(mesh, *h as usize));
            }
            [(_, h1), (_, h2)] => {
                let (h1, h2) = (*h1 as usize, *h2 as usize);
                let (a, b) = half_edge(mesh, h1);
                if half_edge(mesh, h2) == (a, b) {
                    topo.misoriented_edges += 1;
                }
                fans.union(corner_of(mesh, h1, a), corner_of(mesh, h2, a));
                fans.union(corner_of(mesh, h1, b), corner_of(mesh, h2, b));
            }
            _ => topo.non_manifold_edges += 1,
        }
    }

    let mut fan_of_vertex = vec![usize::MAX; mesh.positions.len()];
    let mut split = vec![false; mesh.positions.len()];
    for corner in 0..mesh.triangles.len() * 3 {
        let v = mesh.triangles[corner / 3][corner % 3] as usize;
        let root = fans.find(corner);
        if fan_of_vertex[v] == usize::MAX {
            fan_of_vertex[v] = root;
        } else if fan_of_vertex[v] != root {
            split[v] = true;
        }
    }
    topo.non_manifold_vertices = split.iter().filter(|&&s| s).count();
    topo.boundary_loops = chain_loops(&boundary);
    topo
}

/// Chains directed boundary edges into loops. Where several boundary edges leave one vertex
/// (a non-manifold boundary), any unused one is taken; a chain that cannot close is still
/// reported as one (open) loop so that every boundary edge belongs to exactly one loop.
fn chain_loops(edges: &[(u32, u32)]) -> Vec<Vec<u32>> {
    let mut leaving: HashMap<u32, Vec<usize>> = HashMap::new();
    for (i, &(a, _)) in edges.iter().enumerate() {
        leaving.entry(a).or_default().push(i);
    }
    let mut used = vec![false; edges.len()];
    let mut loops = Vec::new();
    for start in 0..edges.len() {
        if used[start] {
            continue;
        }
        let mut chain = vec![edges[start].0];
        let mut at = start;
        loop {
            used[at] = true;
            let next_vertex = edges[at].1;
            if next_vertex == chain[0] {
                break;
            }
            chain.push(next_vertex);
            let next =
                leaving.get(&next_vertex).and_then(|c| c.iter().copied().find(|&e| !used[e]));
            match next {
                Some(e) => at = e,
                None => break,
            }
        }
        loops.push(chain);
    }
    loops
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    fn tetrahedron() -> Mesh {
        let p = vec![DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z];
        Mesh::new(p, vec![[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]])
    }

    #[test]
    fn closed_tetrahedron_is_closed_manifold_and_oriented() {
        let mesh = tetrahedron();
        let t = topology(&mesh);
        assert_eq!(t.edges, 6);
        assert!(t.is_closed() && t.is_manifold() && t.is_consistently_oriented());
        assert!(mesh.signed_volume() > 0.0);
    }

    #[test]
    fn removing_a_face_leaves_one_hole() {
        let mut mesh = tetrahedron();
        mesh.triangles.pop();
        let t = topology(&mesh);
        assert_eq!(t.boundary_edges, 3);
        assert_eq!(t.boundary_loops.len(), 1);
        assert_eq!(t.boundary_loops[0].len(), 3);
    }

    #[test]
    fn flipped_face_is_misoriented() {
        let mut mesh = tetrahedron();
        mesh.triangles[0].swap(1, 2);
        assert_eq!(topology(&mesh).misoriented_edges, 3);
    }

    #[test]
    fn two_tetrahedra_sharing_a_vertex_make_it_non_manifold() {
        let mut mesh = tetrahedron();
        let far: Vec<DVec3> =
            [DVec3::new(-1., 0., 0.), DVec3::new(0., -1., 0.), DVec3::new(0., 0., -1.)].into();
        mesh.positions.extend(far);
        mesh.triangles.extend([[0, 4, 5], [0, 6, 4], [0, 5, 6], [4, 6, 5]]);
        let t = topology(&mesh);
        assert!(t.is_closed());
        assert_eq!(t.non_manifold_edges, 0);
        assert_eq!(t.non_manifold_vertices, 1);
    }

    #[test]
    fn three_triangles_on_one_edge_is_a_non_manifold_edge() {
        let p = vec![DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z, DVec3::NEG_Y];
        let mesh = Mesh::new(p, vec![[0, 1, 2], [1, 0, 3], [0, 1, 4]]);
        assert_eq!(topology(&mesh).non_manifold_edges, 1);
    }
}
