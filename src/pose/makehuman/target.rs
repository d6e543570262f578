//! Sparse morph targets (`.target` files): lines `vertex dx dy dz` in MakeHuman's frame and
//! units, `#` starting a comment. A body is `base + sum_i w_i target_i`.

use super::{MakeHumanError, read_text, to_canonical};
use glam::DVec3;
use std::path::Path;

/// One morph target, converted to the canonical frame (mm).
#[derive(Debug, Clone, PartialEq)]
pub struct Target {
    /// The vertices it moves (0-based indices into the full vertex list).
    pub indices: Vec<u32>,
    /// How far it moves each of them at weight 1.
    pub deltas: Vec<DVec3>,
}

impl Target {
    /// Reads `file`; every index must be below `vertex_count`.
    pub fn load(file: &Path, vertex_count: usize) -> Result<Self, MakeHumanError> {
        let text = read_text(file)?;
        let mut target = Target { indices: Vec::new(), deltas: Vec::new() };
        for (n, line) in text.lines().enumerate() {
            let line = line.split('#').next().unwrap_or_default();
            let words: Vec<&str> = line.split_whitespace().collect();
            if words.is_empty() {
                continue;
            }
            let bad = |what: &str| MakeHumanError::new(file, format!("line {}: {what}", n + 1));
            let [i, x, y, z] = words[..] else {
                return Err(bad("expected `vertex dx dy dz`"));
            };
            let index: u32 = i.parse().map_err(|_| bad("the vertex index is not an integer"))?;
            if index as usize >= vertex_count {
                return Err(bad(&format!(
                    "vertex {index} is beyond the base mesh's {vertex_count}"
                )));
            }
            let d: Vec<f64> = [x, y, z].iter().filter_map(|w| w.parse().ok()).collect();
            match d[..] {
                [dx, dy, dz] if d.iter().all(|v| v.is_finite()) => {
                    target.indices.push(index);
                    target.deltas.push(to_canonical(dx, dy, dz));
                }
                _ => return Err(bad("an offset needs three finite numbers")),
            }
        }
        Ok(target)
    }

    /// Adds `weight` times this target to `vertices` (the full vertex list).
    pub fn apply(&self, vertices: &mut [DVec3], weight: f64) {
        for (&i, &d) in self.indices.iter().zip(&self.deltas) {
            vertices[i as usize] += weight * d;
        }
    }
}
