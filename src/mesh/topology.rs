//! Edge topology: boundaries (holes), non-manifold edges and vertices, orientation.

use super::Mesh;
use super::adjacency::Incidence;
use rayon::prelude::*;
use rustc_hash::FxHashMap;

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

    /// Human-readable warnings about holes, non-manifold spots and flipped faces.
    pub fn warnings(&self) -> Vec<String> {
        let mut w = Vec::new();
        if !self.boundary_loops.is_empty() {
            w.push(format!("the body has {} holes (boundary loops)", self.boundary_loops.len()));
        }
        if !self.is_manifold() {
            w.push(format!(
                "the body is not manifold: {} edges with more than two faces, {} vertices joining separate fans",
                self.non_manifold_edges, self.non_manifold_vertices
            ));
        }
        if self.misoriented_edges > 0 {
            w.push(format!("{} edges join faces of opposite orientation", self.misoriented_edges));
        }
        w
    }
}

/// Half-edge `h` runs from corner `h % 3` to the next corner of triangle `h / 3`.
fn half_edge(mesh: &Mesh, h: usize) -> (u32, u32) {
    let tri = mesh.triangles[h / 3];
    (tri[h % 3], tri[(h + 1) % 3])
}

/// Analyses the edges of `mesh` in linear time: half-edges are grouped by their lower vertex
/// (a counting sort), and within each small group by their upper vertex; vertex ranges are
/// processed in parallel.
pub fn topology(mesh: &Mesh) -> Topology {
    let by_vertex = Incidence::half_edges_by_lower_vertex(mesh);
    let around = Incidence::triangles(mesh);
    let n = mesh.positions.len();
    let chunk = n.div_ceil(rayon::current_num_threads() * 8).max(1024);
    let parts: Vec<(Topology, Vec<(u32, u32)>)> = (0..n.div_ceil(chunk))
        .into_par_iter()
        .map(|c| {
            let mut topo = Topology::default();
            let mut boundary = Vec::new();
            let mut group: Vec<(u32, u32)> = Vec::new();
            for v in c * chunk..((c + 1) * chunk).min(n) {
                group.clear();
                group.extend(by_vertex.of(v).iter().map(|&h| {
                    let (a, b) = half_edge(mesh, h as usize);
                    (a.max(b), h)
                }));
                group.sort_unstable();
                for run in group.chunk_by(|x, y| x.0 == y.0) {
                    topo.edges += 1;
                    match run {
                        [(_, h)] => {
                            topo.boundary_edges += 1;
                            boundary.push(half_edge(mesh, *h as usize));
                        }
                        [(_, h1), (_, h2)] => {
                            if half_edge(mesh, *h1 as usize) == half_edge(mesh, *h2 as usize) {
                                topo.misoriented_edges += 1;
                            }
                        }
                        _ => topo.non_manifold_edges += 1,
                    }
                }
                if fans(mesh, v as u32, around.of(v)) > 1 {
                    topo.non_manifold_vertices += 1;
                }
            }
            (topo, boundary)
        })
        .collect();
    let mut topo = Topology::default();
    let mut boundary = Vec::new();
    for (t, b) in parts {
        topo.edges += t.edges;
        topo.boundary_edges += t.boundary_edges;
        topo.non_manifold_edges += t.non_manifold_edges;
        topo.non_manifold_vertices += t.non_manifold_vertices;
        topo.misoriented_edges += t.misoriented_edges;
        boundary.extend(b);
    }
    topo.boundary_loops = chain_loops(&boundary);
    topo
}

/// How many fans the triangles around vertex `v` form: triangles are in one fan when they
/// are linked through edges at `v` (sharing `v` and one more vertex).
fn fans(mesh: &Mesh, v: u32, triangles: &[u32]) -> usize {
    let n = triangles.len();
    let mut parent: Vec<usize> = (0..n).collect();
    fn root(parent: &mut [usize], mut i: usize) -> usize {
        while parent[i] != i {
            parent[i] = parent[parent[i]];
            i = parent[i];
        }
        i
    }
    let others = |t: u32| mesh.triangles[t as usize];
    for i in 0..n {
        for j in i + 1..n {
            let (a, b) = (others(triangles[i]), others(triangles[j]));
            if a.iter().any(|&x| x != v && b.contains(&x)) {
                let (ri, rj) = (root(&mut parent, i), root(&mut parent, j));
                parent[ri] = rj;
            }
        }
    }
    (0..n).filter(|&i| root(&mut parent, i) == i).count()
}

/// Chains directed boundary edges into loops. Where several boundary edges leave one vertex
/// (a non-manifold boundary), any unused one is taken; a chain that cannot close is still
/// reported as one (open) loop so that every boundary edge belongs to exactly one loop.
fn chain_loops(edges: &[(u32, u32)]) -> Vec<Vec<u32>> {
    let mut leaving: FxHashMap<u32, Vec<usize>> = FxHashMap::default();
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
        let mut mesh = Mesh::default();
        crate::mesh::shapes::add_tetrahedron(&mut mesh, DVec3::ZERO, 1.0);
        mesh
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
