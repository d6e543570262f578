//! Quadric decimation of a scan denser than the pipeline needs (issue 32). A high-resolution
//! scanner writes 5 million triangles a body, detail far below what a girth, a section or a
//! fitted body model uses; reduced once after reading to [`WORKING_TRIANGLES`], every later step
//! runs at the density it was built and timed on. The simplifier is meshoptimizer's (edge
//! collapses ordered by Garland and Heckbert's quadric error metric, keeping the topology and
//! the edges of holes), through the `meshopt` crate, a widely used binding: a simplifier as
//! fast and careful is a project of its own. Vertices that stay keep their exact positions.

use glam::DVec3;
use rustc_hash::FxHashMap as HashMap;

use super::Mesh;
use super::components::components;

/// The most triangles a scan is worked on with: about twice the synthetic customer's (300k,
/// the density the pipeline's steps and smoothing were tuned on), which keeps a 5M-triangle
/// scan's `reconstruct` within issue 32's 15 s on 2 cores (docs/performance.md).
pub const WORKING_TRIANGLES: usize = 600_000;

/// The largest deviation the simplifier may introduce, as a fraction of the mesh's extent
/// (meshoptimizer's `target_error`): 0.1% of a 1.8 m body, 1.8 mm, within a scanner's noise
/// after smoothing. Where it would exceed this the simplifier stops short of the target.
const MAX_ERROR: f32 = 1e-3;

/// What [`decimate`] did.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Decimation {
    /// Triangles before.
    pub from_triangles: usize,
    /// Triangles after.
    pub to_triangles: usize,
    /// The largest deviation introduced, in the mesh's units.
    pub error: f64,
}

/// `mesh` reduced to at most `target` triangles (fewer where `MAX_ERROR` stops it), or `None`
/// when it has no more than that.
pub fn decimate(mesh: &Mesh, target: usize) -> Option<(Mesh, Decimation)> {
    if mesh.triangles.len() <= target {
        return None;
    }
    let positions: Vec<[f32; 3]> = mesh.positions.iter().map(|p| p.as_vec3().to_array()).collect();
    let adapter =
        meshopt::VertexDataAdapter::new(bytes_of(&positions), std::mem::size_of::<[f32; 3]>(), 0)
            .ok()?;
    let mut relative_error = 0.0f32;
    let kept = meshopt::simplify(
        mesh.triangles.as_flattened(),
        &adapter,
        3 * target,
        MAX_ERROR,
        meshopt::SimplifyOptions::LockBorder,
        Some(&mut relative_error),
    );
    let mut triangles: Vec<[u32; 3]> = kept.chunks_exact(3).map(|t| [t[0], t[1], t[2]]).collect();
    drop_folded_pairs(&mut triangles);
    let mut out = compact(&mesh.positions, &triangles);
    // A fold dropped can leave a sliver apart from the body: the body is the largest piece.
    let found = components(&out);
    if !found.is_one_piece() {
        out.triangles.retain(|t| found.of_vertex[t[0] as usize] == 0);
        out = compact(&out.positions, &out.triangles);
    }
    let extent = mesh.bounds().map_or(0.0, |b| (b.max - b.min).max_element());
    let done = Decimation {
        from_triangles: mesh.triangles.len(),
        to_triangles: out.triangles.len(),
        error: f64::from(relative_error) * extent,
    };
    Some((out, done))
}

/// Drops every triangle whose three corners another triangle also has: where the simplifier
/// collapses a thin fold, it leaves the two sides as one triangle twice, back to back (0.1-0.6%
/// of the triangles on a scan), a pocket of no volume whose edges have four faces.
fn drop_folded_pairs(triangles: &mut Vec<[u32; 3]>) {
    let key = |t: &[u32; 3]| {
        let mut k = *t;
        k.sort_unstable();
        k
    };
    let mut count: HashMap<[u32; 3], u32> =
        HashMap::with_capacity_and_hasher(triangles.len(), Default::default());
    for t in triangles.iter() {
        *count.entry(key(t)).or_default() += 1;
    }
    triangles.retain(|t| count[&key(t)] == 1);
}

/// The mesh of `triangles` over `positions`, with only the vertices they use, in their first
/// use's order. Not [`Mesh::drop_unused_vertices`]: that works on a mesh that owns its
/// positions, and a copy of the scan's 2.4M would land on the decimation's memory peak.
fn compact(positions: &[DVec3], triangles: &[[u32; 3]]) -> Mesh {
    let mut new_index = vec![u32::MAX; positions.len()];
    let mut out = Mesh::default();
    for &i in triangles.iter().flatten() {
        if new_index[i as usize] == u32::MAX {
            new_index[i as usize] = out.positions.len() as u32;
            out.positions.push(positions[i as usize]);
        }
    }
    out.triangles = triangles.iter().map(|t| t.map(|i| new_index[i as usize])).collect();
    out
}

/// The bytes of `positions` for meshoptimizer's vertex view.
fn bytes_of(positions: &[[f32; 3]]) -> &[u8] {
    // SAFETY: `[f32; 3]` is plain data without padding; the slice covers exactly the
    // `positions.len() * 12` initialised bytes of the vector, borrowed for as long as it.
    unsafe {
        std::slice::from_raw_parts(
            positions.as_ptr().cast::<u8>(),
            std::mem::size_of_val(positions),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A sphere of `n` x `2n` quads split in two: a dense closed surface.
    fn sphere(n: u32, radius: f64) -> Mesh {
        let mut mesh = Mesh::default();
        for i in 0..=n {
            for j in 0..2 * n {
                let (t, p) = (
                    std::f64::consts::PI * i as f64 / n as f64,
                    std::f64::consts::PI * j as f64 / n as f64,
                );
                mesh.positions
                    .push(radius * DVec3::new(t.sin() * p.cos(), t.sin() * p.sin(), t.cos()));
            }
        }
        let at = |i: u32, j: u32| i * 2 * n + j % (2 * n);
        for i in 0..n {
            for j in 0..2 * n {
                let (a, b, c, d) = (at(i, j), at(i, j + 1), at(i + 1, j), at(i + 1, j + 1));
                mesh.triangles.push([a, c, b]);
                mesh.triangles.push([b, c, d]);
            }
        }
        mesh
    }

    #[test]
    fn a_dense_sphere_is_reduced_and_stays_on_its_surface() {
        let dense = sphere(200, 100.0);
        let (coarse, done) = decimate(&dense, 5_000).expect("denser than the target");
        // The poles' rows of coincident vertices are borders it keeps: a little over the target.
        assert!((4_000..6_000).contains(&done.to_triangles), "{done:?}");
        assert_eq!(coarse.triangles.len(), done.to_triangles);
        assert!(
            coarse.positions.iter().all(|p| (p.length() - 100.0).abs() < 1e-9),
            "kept vertices stay put"
        );
        assert!(done.error < 1.0, "{done:?}");
        assert!(coarse.triangles.iter().flatten().all(|&i| (i as usize) < coarse.positions.len()));
        assert!(decimate(&coarse, 6_000).is_none(), "already within the target");
    }

    #[test]
    fn a_fold_left_twice_is_dropped_and_so_is_what_it_cut_off() {
        let mut triangles = vec![[0, 1, 2], [2, 1, 0], [1, 2, 3], [0, 3, 1]];
        drop_folded_pairs(&mut triangles);
        assert_eq!(triangles, [[1, 2, 3], [0, 3, 1]]);
        let positions: Vec<DVec3> = (0..5).map(|i| DVec3::splat(f64::from(i))).collect();
        let mesh = compact(&positions, &[[4, 3, 1]]);
        assert_eq!(mesh.positions, [positions[4], positions[3], positions[1]]);
        assert_eq!(mesh.triangles, [[0, 1, 2]]);
    }
}
