//! Test-only topology census of a triangle surface: directed edges, vertex fans, components,
//! boundary loops, Euler characteristic.

use std::collections::HashMap;

use sim::capture::TriangleSurface;

/// Topology of a triangle surface.
#[derive(Debug, Clone, PartialEq)]
pub struct Topology {
    /// Directed edges used more than once, or undirected edges without exactly two triangles
    /// of opposite directions (excluding boundary edges).
    pub bad_edges: usize,
    /// Edges with a single triangle.
    pub boundary_edges: usize,
    /// Vertices whose triangles do not form one fan (or one open fan on a boundary).
    pub non_manifold_vertices: usize,
    /// Connected components (through shared vertices).
    pub components: usize,
    /// Closed boundary loops.
    pub boundary_loops: usize,
    /// Euler characteristic V - E + F over the used vertices.
    pub euler: i64,
    /// Vertices no triangle uses.
    pub unused_vertices: usize,
}

/// Counts directed edges, fans, components and boundary loops.
pub fn topology(s: &TriangleSurface) -> Topology {
    let mut directed: HashMap<(u32, u32), u32> = HashMap::new();
    for t in &s.triangles {
        for e in 0..3 {
            *directed.entry((t[e], t[(e + 1) % 3])).or_insert(0) += 1;
        }
    }
    let mut bad_edges = 0;
    let mut boundary: Vec<(u32, u32)> = Vec::new();
    let mut undirected = 0usize;
    for (&(a, b), &n) in &directed {
        let back = directed.get(&(b, a)).copied().unwrap_or(0);
        if n > 1 || back > 1 {
            bad_edges += 1;
        } else if back == 0 {
            boundary.push((a, b));
        }
        if a < b || back == 0 {
            undirected += 1;
        }
    }
    // Fans: around each vertex, map each triangle's "from" neighbour to its "to" neighbour.
    let mut fans: Vec<Vec<(u32, u32)>> = vec![Vec::new(); s.positions.len()];
    for t in &s.triangles {
        for e in 0..3 {
            fans[t[e] as usize].push((t[(e + 1) % 3], t[(e + 2) % 3]));
        }
    }
    let mut non_manifold_vertices = 0;
    let mut unused_vertices = 0;
    for fan in &fans {
        if fan.is_empty() {
            unused_vertices += 1;
            continue;
        }
        let next: HashMap<u32, u32> = fan.iter().copied().collect();
        if next.len() != fan.len() {
            non_manifold_vertices += 1;
            continue;
        }
        // Start at a fan end if the vertex is on a boundary, else anywhere.
        let targets: std::collections::HashSet<u32> = fan.iter().map(|f| f.1).collect();
        let start = fan.iter().map(|f| f.0).find(|v| !targets.contains(v)).unwrap_or(fan[0].0);
        let (mut v, mut steps) = (start, 0);
        while let Some(&w) = next.get(&v) {
            v = w;
            steps += 1;
            if v == start || steps > fan.len() {
                break;
            }
        }
        if steps != fan.len() {
            non_manifold_vertices += 1;
        }
    }
    // Components over vertices.
    let mut parent: Vec<u32> = (0..s.positions.len() as u32).collect();
    fn find(p: &mut [u32], mut x: u32) -> u32 {
        while p[x as usize] != x {
            p[x as usize] = p[p[x as usize] as usize];
            x = p[x as usize];
        }
        x
    }
    for t in &s.triangles {
        let a = find(&mut parent, t[0]);
        for &v in &t[1..] {
            let b = find(&mut parent, v);
            parent[b as usize] = a;
        }
    }
    let mut roots = std::collections::HashSet::new();
    for t in &s.triangles {
        roots.insert(find(&mut parent, t[0]));
    }
    // Boundary loops: follow boundary edges.
    let next_boundary: HashMap<u32, u32> = boundary.iter().copied().collect();
    let mut seen = std::collections::HashSet::new();
    let mut boundary_loops = 0;
    for &(a, _) in &boundary {
        if seen.contains(&a) {
            continue;
        }
        let mut v = a;
        let mut closed = false;
        for _ in 0..=boundary.len() {
            if !seen.insert(v) {
                closed = v == a;
                break;
            }
            match next_boundary.get(&v) {
                Some(&w) => v = w,
                None => break,
            }
        }
        if closed {
            boundary_loops += 1;
        }
    }
    let used = s.positions.len() - unused_vertices;
    Topology {
        bad_edges,
        boundary_edges: boundary.len(),
        non_manifold_vertices,
        components: roots.len(),
        boundary_loops,
        euler: used as i64 - undirected as i64 + s.triangles.len() as i64,
        unused_vertices,
    }
}
