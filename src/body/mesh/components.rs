//! Connected components: triangles connected through shared vertices.

use super::{Aabb, Mesh};
use glam::DVec3;
use rayon::prelude::*;
use std::ops::Range;
use std::sync::atomic::{AtomicU32, Ordering};

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
    /// How many pieces the mesh has (a vertex no triangle uses is none).
    pub count: usize,
    /// The pieces, largest area first, when there are several; empty for a mesh in one piece
    /// (the common case of a scan: there is nothing to choose between, so its area and box,
    /// a pass over every triangle, are not measured).
    pub parts: Vec<Component>,
    /// For each vertex, the index of its piece in `parts`; [`NO_PIECE`] for a vertex that no
    /// triangle uses.
    pub of_vertex: Vec<u32>,
}

/// The piece of a vertex that no triangle uses.
pub const NO_PIECE: u32 = u32::MAX;

impl Components {
    /// Whether every vertex belongs to the largest piece.
    pub fn is_one_piece(&self) -> bool {
        self.of_vertex.par_iter().all(|&p| p == 0)
    }
}

/// The connected components of `mesh`: a parallel union-find over vertices; where there are
/// several pieces, parallel passes for their triangle counts and areas (over triangles) and
/// boxes (over vertices).
pub fn components(mesh: &Mesh) -> Components {
    let sets = DisjointSets::new(mesh.positions.len());
    mesh.triangles.par_chunks(1 << 12).for_each(|block| {
        for &[a, b, c] in block {
            sets.union(a, b);
            sets.union(a, c);
        }
    });
    let mut of_vertex: Vec<u32> =
        (0..mesh.positions.len() as u32).into_par_iter().map(|v| sets.find(v)).collect();
    // One piece, every vertex in it: one root, vertex 0 (a root is its piece's smallest
    // vertex), so every vertex's piece is already 0.
    let root = |&(v, &r): &(usize, &u32)| r == v as u32;
    if !mesh.triangles.is_empty() && of_vertex.par_iter().enumerate().filter(root).count() == 1 {
        return Components { count: 1, parts: Vec::new(), of_vertex };
    }
    // One piece besides unused vertices: every triangle's root is the first's.
    let first = mesh.triangles.first().map(|t| of_vertex[t[0] as usize]);
    if mesh.triangles.par_iter().all(|t| Some(of_vertex[t[0] as usize]) == first) {
        of_vertex.par_iter_mut().for_each(|r| *r = if Some(*r) == first { 0 } else { NO_PIECE });
        return Components { count: usize::from(first.is_some()), parts: Vec::new(), of_vertex };
    }
    // A piece's root is its smallest vertex: numbering the roots in order numbers the pieces
    // in order of first appearance.
    let roots: Vec<u32> = (0..mesh.positions.len() as u32)
        .into_par_iter()
        .filter(|&v| of_vertex[v as usize] == v)
        .collect();
    of_vertex.par_iter_mut().for_each(|r| *r = roots.partition_point(|&root| root < *r) as u32);

    let piece_of_triangle = |t: usize| of_vertex[mesh.triangles[t][0] as usize];
    let sizes = per_piece(mesh.triangles.len(), piece_of_triangle, roots.len(), |range| {
        (range.len(), range.map(|t| mesh.triangle_area(t)).sum())
    });
    let boxes = per_piece(
        mesh.positions.len(),
        |v| of_vertex[v],
        roots.len(),
        |range| Aabb::around(mesh.positions[range].iter().copied()),
    );
    let parts: Vec<Component> = sizes
        .into_iter()
        .zip(boxes)
        .map(|((triangles, area), bounds)| Component {
            triangles,
            area,
            bounds: bounds.unwrap_or(Aabb { min: DVec3::ZERO, max: DVec3::ZERO }),
        })
        .collect();

    // Largest area first; a vertex without triangles is no piece.
    let mut order: Vec<usize> = (0..parts.len()).filter(|&p| parts[p].triangles > 0).collect();
    order.sort_by(|&a, &b| parts[b].area.total_cmp(&parts[a].area));
    if order.len() < parts.len() || order.iter().enumerate().any(|(r, &id)| r != id) {
        let mut rank = vec![NO_PIECE; parts.len()];
        for (r, &id) in order.iter().enumerate() {
            rank[id] = r as u32;
        }
        of_vertex.par_iter_mut().for_each(|id| *id = rank[*id as usize]);
    }
    let parts: Vec<Component> = order.into_iter().map(|id| parts[id].clone()).collect();
    Components { count: parts.len(), parts, of_vertex }
}

/// Sums something over the items `0..items` of each of `pieces` pieces, in parallel and in a
/// fixed order ([`super::reduce`]): `piece(i)` is item `i`'s piece, `sum` gives the total over
/// a range of items of one piece, and `T::merge` adds totals. Runs of items of one piece are
/// summed at once.
fn per_piece<T: Merge + Default + Clone + Send>(
    items: usize,
    piece: impl Fn(usize) -> u32 + Sync,
    pieces: usize,
    sum: impl Fn(Range<usize>) -> T + Sync,
) -> Vec<T> {
    let empty = || vec![T::default(); pieces];
    let blocks = super::reduce::blocks(items, |block| {
        let mut totals = empty();
        let mut first = block.start;
        while first < block.end {
            let id = piece(first);
            let run_end = (first + 1..block.end).find(|&i| piece(i) != id).unwrap_or(block.end);
            totals[id as usize].merge(sum(first..run_end));
            first = run_end;
        }
        totals
    });
    blocks.into_iter().fold(empty(), |mut x, y| {
        x.iter_mut().zip(y).for_each(|(a, b)| a.merge(b));
        x
    })
}

/// Totals that add up.
trait Merge {
    fn merge(&mut self, other: Self);
}

impl Merge for (usize, f64) {
    fn merge(&mut self, other: Self) {
        self.0 += other.0;
        self.1 += other.1;
    }
}

impl Merge for Option<Aabb> {
    fn merge(&mut self, other: Self) {
        *self = match (*self, other) {
            (Some(a), Some(b)) => Some(Aabb { min: a.min.min(b.min), max: a.max.max(b.max) }),
            (a, b) => a.or(b),
        };
    }
}

/// Union-find that many threads can use at once: a root is linked under the smaller of two
/// roots by compare-and-swap, so parents only ever decrease (no cycles, and a piece's root is
/// its smallest member), and finds halve paths as they go (the ECL-CC scheme).
struct DisjointSets {
    parent: Vec<AtomicU32>,
}

impl DisjointSets {
    fn new(n: usize) -> Self {
        DisjointSets { parent: (0..n as u32).into_par_iter().map(AtomicU32::new).collect() }
    }

    fn find(&self, mut x: u32) -> u32 {
        loop {
            let p = self.parent[x as usize].load(Ordering::Relaxed);
            if p == x {
                return x;
            }
            // Any value stored is an ancestor of x, whatever other threads do meanwhile.
            let g = self.parent[p as usize].load(Ordering::Relaxed);
            if g != p {
                self.parent[x as usize].store(g, Ordering::Relaxed);
            }
            x = g;
        }
    }

    fn union(&self, a: u32, b: u32) {
        loop {
            let (a, b) = (self.find(a), self.find(b));
            if a == b {
                return;
            }
            let (high, low) = (a.max(b), a.min(b));
            let linked = self.parent[high as usize].compare_exchange(
                high,
                low,
                Ordering::Relaxed,
                Ordering::Relaxed,
            );
            if linked.is_ok() {
                return;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::body::mesh::shapes::add_tetrahedron;
    use proptest::prelude::*;

    #[test]
    fn pieces_come_largest_first_and_unused_vertices_belong_to_none() {
        let mut mesh = Mesh::default();
        add_tetrahedron(&mut mesh, DVec3::ZERO, 1.0);
        mesh.positions.push(DVec3::splat(7.0)); // used by no triangle
        add_tetrahedron(&mut mesh, DVec3::new(5.0, 0.0, 0.0), 2.0);
        let found = components(&mesh);
        assert_eq!(found.parts.len(), 2);
        assert!(found.parts[0].area > found.parts[1].area);
        assert!((found.parts[0].area - 4.0 * found.parts[1].area).abs() < 1e-12);
        assert_eq!(found.parts[0].triangles, 4);
        assert_eq!(found.parts[0].bounds.min, DVec3::new(5.0, 0.0, 0.0));
        assert_eq!(found.parts[0].bounds.max, DVec3::new(7.0, 2.0, 2.0));
        assert_eq!(&found.of_vertex[..4], &[1; 4]);
        assert_eq!(found.of_vertex[4], NO_PIECE);
        assert_eq!(&found.of_vertex[5..], &[0; 4]);
        assert!(!found.is_one_piece());
    }

    #[test]
    fn one_piece_is_counted_not_measured() {
        let mut mesh = Mesh::default();
        add_tetrahedron(&mut mesh, DVec3::ZERO, 1.0);
        let found = components(&mesh);
        assert_eq!((found.count, found.parts.len()), (1, 0));
        assert!(found.is_one_piece());
        mesh.positions.push(DVec3::splat(7.0)); // used by no triangle
        let found = components(&mesh);
        assert_eq!((found.count, found.parts.len()), (1, 0));
        assert_eq!(found.of_vertex, [0, 0, 0, 0, NO_PIECE]);
        assert!(!found.is_one_piece());
        mesh.triangles.clear();
        let found = components(&mesh);
        assert_eq!((found.count, found.parts.len()), (0, 0));
        assert!(found.of_vertex.iter().all(|&p| p == NO_PIECE));
    }

    /// The pieces of `triangles` over `n` vertices by a plain sequential search: for each
    /// vertex, the smallest vertex of its piece (`None` if unused).
    fn reference(n: usize, triangles: &[[u32; 3]]) -> Vec<Option<usize>> {
        let mut neighbours = vec![Vec::new(); n];
        for &[a, b, c] in triangles {
            for (x, y) in [(a, b), (b, c), (c, a)] {
                neighbours[x as usize].push(y as usize);
                neighbours[y as usize].push(x as usize);
            }
        }
        let mut smallest = vec![None; n];
        for start in 0..n {
            if smallest[start].is_some() || neighbours[start].is_empty() {
                continue;
            }
            let mut stack = vec![start];
            smallest[start] = Some(start);
            while let Some(v) = stack.pop() {
                for &w in &neighbours[v] {
                    if smallest[w].is_none() {
                        smallest[w] = Some(start);
                        stack.push(w);
                    }
                }
            }
        }
        smallest
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(64))]
        /// The parallel union-find partitions vertices exactly as a sequential search does
        /// (enough triangles that several threads link the same pieces).
        #[test]
        fn same_pieces_as_a_sequential_search(
            n in 3usize..3000,
            picks in prop::collection::vec(any::<[u32; 3]>(), 1..20_000),
        ) {
            let positions = (0..n).map(|i| DVec3::new(i as f64, (i * i % 7) as f64, (i % 3) as f64)).collect();
            let triangles: Vec<[u32; 3]> = picks.iter().map(|t| t.map(|v| v % n as u32)).collect();
            let mesh = Mesh::new(positions, triangles);
            let found = components(&mesh);
            let expected = reference(n, &mesh.triangles);
            for (a, root) in expected.iter().enumerate() {
                prop_assert_eq!(found.of_vertex[a] == NO_PIECE, root.is_none());
            }
            // Same partition: two vertices share a piece exactly when they share a reference root.
            let mut piece_of_root = std::collections::HashMap::new();
            for (a, root) in expected.iter().enumerate() {
                if let Some(root) = root {
                    let piece = *piece_of_root.entry(root).or_insert(found.of_vertex[a]);
                    prop_assert_eq!(piece, found.of_vertex[a]);
                }
            }
            prop_assert_eq!(piece_of_root.len(), found.count);
            // Several pieces are measured; one is the whole mesh.
            prop_assert_eq!(found.parts.len(), if found.count > 1 { found.count } else { 0 });
            if found.count > 1 {
                let triangles: usize = found.parts.iter().map(|p| p.triangles).sum();
                prop_assert_eq!(triangles, mesh.triangles.len());
            }
        }
    }
}
