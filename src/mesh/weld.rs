//! Merging vertices that sit at exactly the same position.
//!
//! STL stores every triangle with its own corners, and OBJ readers split vertices per group;
//! merging bit-identical positions restores the connectivity the scanner meant.

use super::Mesh;
use std::collections::HashMap;

/// Merges vertices with bit-identical positions (`-0.0` and `0.0` count as one); returns how
/// many vertices were merged away. Vertices no triangle uses are dropped too.
pub(super) fn weld_identical(mesh: &mut Mesh) -> usize {
    let before = mesh.positions.len();
    let mut first_at: HashMap<[u64; 3], u32> = HashMap::with_capacity(before);
    let mut remap = Vec::with_capacity(before);
    for (i, p) in mesh.positions.iter().enumerate() {
        let key = p.to_array().map(|c| (c + 0.0).to_bits());
        remap.push(*first_at.entry(key).or_insert(i as u32));
    }
    for tri in &mut mesh.triangles {
        for i in tri.iter_mut() {
            *i = remap[*i as usize];
        }
    }
    let distinct = first_at.len();
    mesh.drop_unused_vertices();
    before - distinct
}
