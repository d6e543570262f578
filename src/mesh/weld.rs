//! Merging vertices that sit at exactly the same position.
//!
//! STL stores every triangle with its own corners, and OBJ readers split vertices per group;
//! merging bit-identical positions restores the connectivity the scanner meant.

use super::Mesh;
use rayon::prelude::*;

/// Merges vertices with bit-identical positions (`-0.0` and `0.0` count as one) into the first
/// of them; returns how many were merged away. Vertices no triangle uses are dropped too.
/// A parallel sort of the positions' bit patterns finds the duplicates.
pub(super) fn weld_identical(mesh: &mut Mesh) -> usize {
    let mut keyed: Vec<([u64; 3], u32)> = mesh
        .positions
        .par_iter()
        .enumerate()
        .map(|(i, p)| (p.to_array().map(|c| (c + 0.0).to_bits()), i as u32))
        .collect();
    keyed.par_sort_unstable();
    let mut remap: Vec<u32> = (0..mesh.positions.len() as u32).collect();
    let mut merged = 0;
    for run in keyed.chunk_by(|a, b| a.0 == b.0) {
        for &(_, i) in &run[1..] {
            remap[i as usize] = run[0].1;
            merged += 1;
        }
    }
    if merged > 0 {
        for tri in &mut mesh.triangles {
            *tri = tri.map(|i| remap[i as usize]);
        }
    }
    mesh.drop_unused_vertices();
    merged
}
