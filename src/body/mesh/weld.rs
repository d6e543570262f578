//! Merging vertices that sit at exactly the same position.
//!
//! STL stores every triangle with its own corners, and OBJ readers split vertices per group;
//! merging bit-identical positions restores the connectivity the scanner meant.

use super::Mesh;
use rayon::prelude::*;
use rustc_hash::FxHasher;
use std::hash::{Hash, Hasher};

/// Merges vertices with bit-identical positions (`-0.0` and `0.0` count as one) into the first
/// of them; returns how many were merged away. When some were, vertices no triangle uses are
/// dropped too.
///
/// A radix sort of `hash << 32 | index` keys by hash brings equal positions together (in index
/// order); only runs of equal hashes (duplicates, and rare collisions) are compared
/// coordinate by coordinate.
pub(super) fn weld_identical(mesh: &mut Mesh) -> usize {
    let bits = |i: u32| mesh.positions[i as usize].to_array().map(|c| (c + 0.0).to_bits());
    let hash = |i: u32| {
        let mut h = FxHasher::default();
        bits(i).hash(&mut h);
        h.finish() >> 32
    };
    let mut keys: Vec<u64> = (0..mesh.positions.len() as u32)
        .into_par_iter()
        .map(|i| hash(i) << 32 | u64::from(i))
        .collect();
    // By hash, stably: equal hashes stay in index order (the order of the whole keys).
    radsort::sort_by_key(&mut keys, |k| (k >> 32) as u32);
    let mut remap: Vec<u32> = Vec::new();
    let mut merged = 0;
    for run in keys.chunk_by(|a, b| a >> 32 == b >> 32).filter(|run| run.len() > 1) {
        let mut same: Vec<([u64; 3], u32)> =
            run.iter().map(|&k| (bits(k as u32), k as u32)).collect();
        same.sort_unstable();
        for group in same.chunk_by(|a, b| a.0 == b.0) {
            for &(_, i) in &group[1..] {
                if remap.is_empty() {
                    remap = (0..mesh.positions.len() as u32).collect();
                }
                remap[i as usize] = group[0].1;
                merged += 1;
            }
        }
    }
    if merged > 0 {
        mesh.triangles.par_iter_mut().for_each(|tri| *tri = tri.map(|i| remap[i as usize]));
        mesh.drop_unused_vertices();
    }
    merged
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    #[test]
    fn a_triangle_soup_is_welded_into_the_first_of_each_group() {
        let (a, b, c, d) = (DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z);
        // Two triangles with their own corners, sharing the edge a-b; `-0.0` equals `0.0`.
        let minus_zero = DVec3::new(-0.0, 0.0, -0.0);
        let mut mesh = Mesh::new(vec![a, b, c, b, minus_zero, d], vec![[0, 1, 2], [3, 4, 5]]);
        assert_eq!(weld_identical(&mut mesh), 2);
        assert_eq!(mesh.positions, vec![a, b, c, d]);
        assert_eq!(mesh.triangles, vec![[0, 1, 2], [1, 0, 3]]);
    }

    #[test]
    fn distinct_positions_are_left_alone() {
        let positions: Vec<DVec3> = (0..1000).map(|i| DVec3::new(i as f64, 0.5, -1.0)).collect();
        let triangles = (0..998).map(|i| [i, i + 1, i + 2]).collect();
        let mut mesh = Mesh::new(positions.clone(), triangles);
        assert_eq!(weld_identical(&mut mesh), 0);
        assert_eq!(mesh.positions, positions);
    }
}
