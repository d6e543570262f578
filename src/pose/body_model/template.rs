//! The template's mirror map: the hm08 skin is exactly mirror-symmetric about the plane x = 0,
//! so every vertex has a partner at `(-x, y, z)` (the 188 vertices on the plane are their own).

use glam::DVec3;
use std::collections::HashMap;

/// The reflection about the symmetry plane x = 0.
pub fn reflect(p: DVec3) -> DVec3 {
    DVec3::new(-p.x, p.y, p.z)
}

/// For each vertex, the index of its mirror partner (itself on the plane x = 0), or the first
/// vertex that has none.
pub fn mirror_map(positions: &[DVec3]) -> Result<Vec<u32>, usize> {
    // Exact keys: the base mesh is symmetric to the last bit (`+ 0.0` folds -0 into 0).
    let key = |p: DVec3| [p.x + 0.0, p.y + 0.0, p.z + 0.0].map(f64::to_bits);
    let index: HashMap<[u64; 3], u32> =
        positions.iter().enumerate().map(|(i, &p)| (key(p), i as u32)).collect();
    positions
        .iter()
        .enumerate()
        .map(|(i, &p)| index.get(&key(reflect(p))).copied().ok_or(i))
        .collect()
}

/// A per-vertex field (positions or offsets) reflected: `mirrored[i] = S field[mirror[i]]`.
pub fn mirrored(field: &[DVec3], mirror: &[u32]) -> Vec<DVec3> {
    mirror.iter().map(|&m| reflect(field[m as usize])).collect()
}

/// The mean of a field and its mirror image: exactly symmetric.
pub fn symmetrised(field: &[DVec3], mirror: &[u32]) -> Vec<DVec3> {
    field.iter().zip(mirrored(field, mirror)).map(|(&a, b)| (a + b) / 2.0).collect()
}

/// The largest distance between a field and its mirror image (0 for a symmetric one).
pub fn asymmetry(field: &[DVec3], mirror: &[u32]) -> f64 {
    field.iter().zip(mirrored(field, mirror)).map(|(&a, b)| a.distance(b)).fold(0.0, f64::max)
}
