//! Edge topology: boundaries (holes), non-manifold edges and vertices, orientation.

use super::Mesh;
use super::adjacency::Incidence;
use rayon::prelude::*;

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
            let n = self.boundary_loops.len();
            let holes = if n == 1 { "hole" } else { "holes" };
            w.push(format!("the body has {n} {holes} (boundary loops)"));
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

/// Whether triangle `tri` runs from `a` to `b` (has the half-edge a -> b).
fn runs(tri: [u32; 3], a: u32, b: u32) -> bool {
    (0..3).any(|k| tri[k] == a && tri[(k + 1) % 3] == b)
}

/// What one vertex adds to the topology: the edges it owns (those to higher-numbered
/// vertices), the boundary half-edges among them, and whether its triangles form more than
/// one fan.
#[derive(Default)]
struct Scratch {
    /// `other corner << 32 | index in the vertex's triangle list`, for every triangle at the
    /// vertex (packed: one integer sort).
    corners: Vec<u64>,
    /// Union-find parents over the vertex's triangles.
    parent: Vec<u32>,
}

/// Analyses the edges of `mesh` in linear time from one incidence table (the triangles round
/// each vertex, a counting sort): each vertex sorts its triangles' other corners, so that
/// the triangles sharing an edge come together; that classifies the edges it owns (to a
/// higher-numbered vertex: each edge once) and links its fans. Vertex ranges run in parallel.
/// Triangles with a repeated corner (which cleaning drops) add no edge at that corner.
pub fn topology(mesh: &Mesh) -> Topology {
    let around = Incidence::triangles(mesh);
    let n = mesh.positions.len();
    let chunk = n.div_ceil(rayon::current_num_threads() * 8).max(1024);
    let parts: Vec<Part> = (0..n.div_ceil(chunk))
        .into_par_iter()
        .map(|c| {
            let mut topo = Topology::default();
            let mut boundary = Vec::new();
            let mut scratch = Scratch::default();
            for v in c * chunk..((c + 1) * chunk).min(n) {
                let fans =
                    vertex(mesh, v as u32, around.of(v), &mut scratch, &mut topo, &mut boundary);
                if fans > 1 {
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

/// What one range of vertices adds: its counts and its boundary half-edges.
type Part = (Topology, Vec<(u32, u32)>);

/// Vertex `v` with its `triangles` (in increasing order): classifies the edges from `v` to
/// higher-numbered vertices into `topo` (boundary half-edges, in the direction their
/// triangle runs, to `boundary`) and returns how many fans the triangles form: triangles are
/// in one fan when they are linked through edges at `v`. Sorting the triangles' other
/// corners brings the ones sharing an edge together, so a vertex of degree d costs
/// O(d log d), not the O(d²) of comparing every pair (a million-triangle fan round one vertex
/// is a valid mesh).
fn vertex(
    mesh: &Mesh,
    v: u32,
    triangles: &[u32],
    scratch: &mut Scratch,
    topo: &mut Topology,
    boundary: &mut Vec<(u32, u32)>,
) -> usize {
    let Scratch { corners, parent } = scratch;
    corners.clear();
    for (i, &t) in triangles.iter().enumerate() {
        // A triangle is listed once per corner at `v`: only a degenerate one twice.
        if i > 0 && triangles[i - 1] == t {
            continue;
        }
        let others = mesh.triangles[t as usize].into_iter().filter(|&x| x != v);
        corners.extend(others.map(|x| u64::from(x) << 32 | i as u64));
    }
    corners.sort_unstable();
    parent.clear();
    parent.extend(0..triangles.len() as u32);
    fn root(parent: &mut [u32], mut i: u32) -> u32 {
        while parent[i as usize] != i {
            parent[i as usize] = parent[parent[i as usize] as usize];
            i = parent[i as usize];
        }
        i
    }
    let tri = |i: u32| mesh.triangles[triangles[i as usize] as usize];
    let corner = |k: u64| (k >> 32) as u32;
    let index = |k: u64| k as u32;
    for run in corners.chunk_by(|&a, &b| corner(a) == corner(b)) {
        let x = corner(run[0]);
        if x > v {
            topo.edges += 1;
            match *run {
                [i] => {
                    topo.boundary_edges += 1;
                    boundary.push(if runs(tri(index(i)), v, x) { (v, x) } else { (x, v) });
                }
                [i, j] => {
                    if runs(tri(index(i)), v, x) == runs(tri(index(j)), v, x) {
                        topo.misoriented_edges += 1;
                    }
                }
                _ => topo.non_manifold_edges += 1,
            }
        }
        for pair in run.windows(2) {
            let (a, b) = (root(parent, index(pair[0])), root(parent, index(pair[1])));
            parent[a as usize] = b;
        }
    }
    let listed = |i: &u32| *i == 0 || triangles[*i as usize - 1] != triangles[*i as usize];
    (0..triangles.len() as u32).filter(|i| listed(i) && root(parent, *i) == *i).count()
}

/// Chains directed boundary edges into loops. Where several boundary edges leave one vertex
/// (a non-manifold boundary), the first unused one is taken; a chain that cannot close is
/// still reported as one (open) loop so that every boundary edge belongs to exactly one loop.
/// The edges leaving each vertex are grouped by a counting sort over the vertices (two flat
/// arrays, no hashing and no list per vertex: an open mesh with a million boundary edges stays
/// in the caches' reach) and each is taken from its group once: linear time, however many
/// edges meet at a vertex.
fn chain_loops(edges: &[(u32, u32)]) -> Vec<Vec<u32>> {
    let vertices = edges.iter().map(|&(a, b)| a.max(b) as usize + 1).max().unwrap_or(0);
    // `next[v]..first[v + 1]`: the not yet taken edges leaving v, in edge order.
    let mut first = vec![0u32; vertices + 1];
    for &(a, _) in edges {
        first[a as usize + 1] += 1;
    }
    for v in 0..vertices {
        first[v + 1] += first[v];
    }
    let mut next = first.clone();
    let mut leaving = vec![0u32; edges.len()];
    for (i, &(a, _)) in edges.iter().enumerate() {
        leaving[next[a as usize] as usize] = i as u32;
        next[a as usize] += 1;
    }
    next.copy_from_slice(&first);
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
            let v = next_vertex as usize;
            let mut found = None;
            while next[v] < first[v + 1] {
                let e = leaving[next[v] as usize] as usize;
                next[v] += 1;
                if !used[e] {
                    found = Some(e);
                    break;
                }
            }
            match found {
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
        crate::body::mesh::shapes::add_tetrahedron(&mut mesh, DVec3::ZERO, 1.0);
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
    fn fans_round_one_vertex_are_counted_in_linear_time() {
        // A closed disk of n triangles round vertex 0 (one fan), then the same disk cut into
        // two half-disks that touch only at the centre (two fans).
        let n = 200_000u32;
        let mut p = vec![DVec3::ZERO];
        p.extend((0..n).map(|i| {
            let a = std::f64::consts::TAU * f64::from(i) / f64::from(n);
            DVec3::new(a.cos(), a.sin(), 0.0)
        }));
        let disk: Vec<[u32; 3]> = (0..n).map(|i| [0, 1 + i, 1 + (i + 1) % n]).collect();
        let mesh = Mesh::new(p.clone(), disk.clone());
        let t = topology(&mesh);
        assert_eq!((t.non_manifold_vertices, t.boundary_loops.len()), (0, 1));
        let mut cut = disk;
        cut[(n / 2) as usize - 1][2] = n + 1;
        cut[n as usize - 1][2] = n + 2;
        p.extend([p[1 + (n / 2) as usize], p[1]]);
        let t = topology(&Mesh::new(p, cut));
        assert_eq!(t.non_manifold_vertices, 1);
        assert_eq!(t.boundary_edges, n as usize + 4, "the rim and four radial edges");
    }

    #[test]
    fn boundary_loops_through_one_vertex_of_many_triangles() {
        // n separate triangles sharing only vertex 0: n fans, n boundary loops.
        let n = 100_000u32;
        let p: Vec<DVec3> =
            (0..=2 * n).map(|i| DVec3::new(f64::from(i), f64::from(i % 7), 0.0)).collect();
        let star: Vec<[u32; 3]> = (0..n).map(|i| [0, 1 + 2 * i, 2 + 2 * i]).collect();
        let t = topology(&Mesh::new(p, star));
        assert_eq!(t.non_manifold_vertices, 1);
        assert_eq!(t.boundary_loops.len(), n as usize);
        assert!(t.boundary_loops.iter().all(|l| l.len() == 3));
    }

    #[test]
    fn three_triangles_on_one_edge_is_a_non_manifold_edge() {
        let p = vec![DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z, DVec3::NEG_Y];
        let mesh = Mesh::new(p, vec![[0, 1, 2], [1, 0, 3], [0, 1, 4]]);
        assert_eq!(topology(&mesh).non_manifold_edges, 1);
    }
}
