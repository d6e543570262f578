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

/// What one vertex adds to the topology: the edges it owns (those to higher-numbered
/// vertices), the boundary half-edges among them, and whether its triangles form more than
/// one fan.
#[derive(Default)]
struct Scratch {
    /// `neighbour << 32 | triangle's place in the vertex's ring << 1 | 1 if the triangle runs
    /// from the vertex to the neighbour`, two for every triangle at the vertex (packed: one
    /// integer sort).
    corners: Vec<u64>,
    /// Union-find parents over the vertex's triangles.
    parent: Vec<u32>,
}

/// Analyses the edges of `mesh` in linear time from one incidence table (each vertex's ring:
/// its triangles' other two corners, a counting sort): each vertex sorts its ring's corners,
/// so that the triangles sharing an edge come together; that classifies the edges it owns
/// (to a higher-numbered vertex: each edge once) and links its fans. Vertex ranges run in
/// parallel. Triangles with a repeated corner (which cleaning drops) are left out.
pub fn topology(mesh: &Mesh) -> Topology {
    let rings = Incidence::rings(mesh);
    let n = mesh.positions.len();
    let chunk = n.div_ceil(rayon::current_num_threads() * 8).max(1024);
    let parts: Vec<Part> = (0..n.div_ceil(chunk))
        .into_par_iter()
        .map(|c| {
            let mut topo = Topology::default();
            let mut boundary = Vec::new();
            let mut scratch = Scratch::default();
            for v in c * chunk..((c + 1) * chunk).min(n) {
                let (v, ring) = (v as u32, rings.of(v));
                if let Some(owned) = closed_fan(v, ring) {
                    topo.edges += owned;
                } else if vertex(v, ring, &mut scratch, &mut topo, &mut boundary) > 1 {
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

/// Rings up to this many triangles are tried as [`closed_fan`]s: a scan's vertices have about
/// six; a longer ring goes to [`vertex`], whose cost grows as d log d rather than d².
const SMALL_RING: usize = 16;

/// The common case, tried first: `v`'s `ring` is one closed fan of manifold, consistently
/// oriented edges (each neighbour is the next corner of exactly one triangle and the previous
/// corner of exactly one other). Then it returns the number of edges `v` owns (to
/// higher-numbered neighbours), and [`vertex`] would find nothing else; `None` otherwise.
///
/// Each triangle's neighbour across its edge `v -> next` is the first triangle whose previous
/// corner is that `next`; walking from triangle to neighbour must come back to the first after
/// exactly d steps. That makes the neighbour map a single cycle through all d triangles, hence
/// one-to-one: no two triangles share a next corner (they would share a neighbour), none
/// shares its previous corner with an earlier one (it would never be reached), and every next
/// corner is a previous one: each edge at `v` has one triangle running out along it and one
/// running in, and the triangles are one fan.
fn closed_fan(v: u32, ring: &[[u32; 2]]) -> Option<usize> {
    let d = ring.len();
    if !(3..=SMALL_RING).contains(&d) {
        return None;
    }
    let mut across = [0u8; SMALL_RING];
    for (i, &[next, _]) in ring.iter().enumerate() {
        across[i] = ring.iter().position(|&[_, prev]| prev == next)? as u8;
    }
    let mut at = 0;
    for step in 1..=d {
        at = across[at] as usize;
        if at == 0 {
            return (step == d).then(|| ring.iter().filter(|&&[next, _]| next > v).count());
        }
    }
    None
}

/// What one range of vertices adds: its counts and its boundary half-edges.
type Part = (Topology, Vec<(u32, u32)>);

/// Vertex `v` with its `ring` ([`Incidence::rings`]): classifies the edges from `v` to
/// higher-numbered vertices into `topo` (boundary half-edges, in the direction their
/// triangle runs, to `boundary`) and returns how many fans the triangles form: triangles are
/// in one fan when they are linked through edges at `v`. Sorting the ring's corners brings
/// the triangles sharing an edge together, so a vertex of degree d costs O(d log d), not the
/// O(d²) of comparing every pair (a million-triangle fan round one vertex is a valid mesh).
fn vertex(
    v: u32,
    ring: &[[u32; 2]],
    scratch: &mut Scratch,
    topo: &mut Topology,
    boundary: &mut Vec<(u32, u32)>,
) -> usize {
    let Scratch { corners, parent } = scratch;
    corners.clear();
    for (i, &[next, prev]) in ring.iter().enumerate() {
        let i = (i as u64) << 1;
        corners.extend([u64::from(next) << 32 | i | 1, u64::from(prev) << 32 | i]);
    }
    corners.sort_unstable();
    parent.clear();
    parent.extend(0..ring.len() as u32);
    fn root(parent: &mut [u32], mut i: u32) -> u32 {
        while parent[i as usize] != i {
            parent[i as usize] = parent[parent[i as usize] as usize];
            i = parent[i as usize];
        }
        i
    }
    let corner = |k: u64| (k >> 32) as u32;
    let index = |k: u64| (k as u32) >> 1;
    let outward = |k: u64| k & 1 == 1;
    for run in corners.chunk_by(|&a, &b| corner(a) == corner(b)) {
        let x = corner(run[0]);
        if x > v {
            topo.edges += 1;
            match *run {
                [i] => {
                    topo.boundary_edges += 1;
                    boundary.push(if outward(i) { (v, x) } else { (x, v) });
                }
                [i, j] => {
                    if outward(i) == outward(j) {
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
    (0..ring.len() as u32).filter(|&i| root(parent, i) == i).count()
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

    /// An octahedron: closed, every vertex a ring of four.
    fn octahedron() -> Vec<[u32; 3]> {
        vec![[0, 2, 4], [2, 1, 4], [1, 3, 4], [3, 0, 4], [2, 0, 5], [1, 2, 5], [3, 1, 5], [0, 3, 5]]
    }

    /// Whether `v`'s ring is one closed fan of manifold, consistently oriented edges, found
    /// the slow way: [`vertex`] counts one fan, and every neighbour is the next corner of
    /// exactly one triangle and the previous corner of exactly one.
    fn reference_closed_fan(v: u32, ring: &[[u32; 2]]) -> Option<usize> {
        let mut uses = std::collections::BTreeMap::<u32, (usize, usize)>::new();
        for &[next, prev] in ring {
            uses.entry(next).or_default().0 += 1;
            uses.entry(prev).or_default().1 += 1;
        }
        let fans = vertex(v, ring, &mut Scratch::default(), &mut Topology::default(), &mut vec![]);
        let closed = fans == 1 && uses.values().all(|&u| u == (1, 1));
        (closed && (3..=SMALL_RING).contains(&ring.len()))
            .then(|| uses.keys().filter(|&&x| x > v).count())
    }

    #[test]
    fn a_closed_surface_takes_the_closed_fan_path_at_every_vertex() {
        let mesh = Mesh::new(vec![DVec3::ZERO; 6], octahedron());
        let rings = Incidence::rings(&mesh);
        for v in 0..6 {
            assert!(closed_fan(v, rings.of(v as usize)).is_some(), "vertex {v}");
        }
        assert_eq!(topology(&mesh), Topology { edges: 12, ..Topology::default() });
    }

    proptest::proptest! {
        #![proptest_config(proptest::prelude::ProptestConfig::with_cases(256))]
        /// The closed-fan shortcut says yes exactly where the general pass would find a closed
        /// manifold fan, and then owns the same edges: on octahedra with faces dropped,
        /// flipped, repeated and added at random.
        #[test]
        fn the_closed_fan_shortcut_agrees_with_the_general_pass(
            copies in 1usize..4,
            edits in proptest::collection::vec((0u8..4, proptest::prelude::any::<[u32; 3]>()), 0..6),
        ) {
            let mut triangles: Vec<[u32; 3]> = (0..copies as u32)
                .flat_map(|c| octahedron().into_iter().map(move |t| t.map(|v| v + 6 * c)))
                .collect();
            let n = 6 * copies as u32;
            for (kind, [a, b, c]) in edits {
                let pick = a as usize % triangles.len();
                match kind {
                    0 => { triangles.remove(pick); }
                    1 => triangles[pick].swap(1, 2),
                    2 => triangles.push(triangles[pick]),
                    _ => triangles.push([a % n, b % n, c % n]),
                }
                if triangles.is_empty() {
                    break;
                }
            }
            let mesh = Mesh::new(vec![DVec3::ZERO; n as usize], triangles);
            let rings = Incidence::rings(&mesh);
            for v in 0..n {
                let ring = rings.of(v as usize);
                proptest::prop_assert_eq!(closed_fan(v, ring), reference_closed_fan(v, ring));
            }
        }
    }
}
