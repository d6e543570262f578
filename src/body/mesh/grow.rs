//! Region growing over triangles that share a vertex.

use super::Mesh;
use super::adjacency::Incidence;

/// The triangles reached from `seeds` (one flag per triangle) by stepping to triangles that
/// share a vertex and that `admit` accepts (by index): the seeds and everything so reached.
pub fn grow(mesh: &Mesh, seeds: &[bool], admit: impl Fn(usize) -> bool) -> Vec<bool> {
    debug_assert_eq!(seeds.len(), mesh.triangles.len(), "a flag per triangle");
    let mut reached = seeds.to_vec();
    let mut front: Vec<usize> = (0..seeds.len()).filter(|&t| seeds[t]).collect();
    if front.is_empty() {
        return reached;
    }
    let around = Incidence::triangles(mesh);
    while let Some(t) = front.pop() {
        for &v in &mesh.triangles[t] {
            for &n in around.of(v as usize) {
                let n = n as usize;
                if !reached[n] && admit(n) {
                    reached[n] = true;
                    front.push(n);
                }
            }
        }
    }
    reached
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    /// A strip of four triangles in a row, each sharing an edge with the next.
    fn strip() -> Mesh {
        let positions = (0..6).map(|i| DVec3::new((i / 2) as f64, (i % 2) as f64, 0.0)).collect();
        Mesh { positions, triangles: vec![[0, 2, 1], [1, 2, 3], [2, 4, 3], [3, 4, 5]] }
    }

    #[test]
    fn growth_stops_at_a_triangle_not_admitted() {
        let mesh = strip();
        let reached = grow(&mesh, &[true, false, false, false], |t| t != 2);
        // Triangle 3 shares vertex 3 with triangle 1, so it is reached around triangle 2.
        assert_eq!(reached, [true, true, false, true]);
        let reached = grow(&mesh, &[true, false, false, false], |t| t == 1);
        assert_eq!(reached, [true, true, false, false]);
    }

    #[test]
    fn no_seed_reaches_nothing() {
        assert_eq!(grow(&strip(), &[false; 4], |_| true), [false; 4]);
    }
}
