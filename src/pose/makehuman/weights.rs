//! `rigs/default_weights.mhw`: per bone, the vertices it moves and how much
//! (`{"weights": {bone: [[vertex, weight], ...]}}`).

use super::{MakeHumanError, Rig, read_text};
use crate::pose::skinning::SkinWeights;
use serde::Deserialize;
use std::collections::BTreeMap;
use std::path::Path;

#[derive(Deserialize)]
struct FileWeights {
    weights: BTreeMap<String, Vec<(u32, f64)>>,
}

/// Reads `file` into per-vertex weights over `rig`'s bones, normalised to sum 1 per vertex
/// (the file's sums are 0.95-1.06). Unknown bones, out-of-range or unweighted vertices and
/// negative or non-finite weights are errors.
pub fn load(file: &Path, rig: &Rig, vertex_count: usize) -> Result<SkinWeights, MakeHumanError> {
    let bad = |what: String| MakeHumanError::new(file, what);
    let parsed: FileWeights = serde_json::from_str(&read_text(file)?)
        .map_err(|e| bad(format!("not a MakeHuman weights file: {e}")))?;
    let mut per_vertex: Vec<Vec<(usize, f64)>> = vec![Vec::new(); vertex_count];
    for (name, list) in &parsed.weights {
        let bone = rig
            .bone(name)
            .ok_or_else(|| bad(format!("weights.{name}: no such bone in the rig")))?;
        for &(v, w) in list {
            if v as usize >= vertex_count || !(w.is_finite() && w >= 0.0) {
                return Err(bad(format!(
                    "weights.{name}: [{v}, {w}] needs a vertex below {vertex_count} and a weight >= 0"
                )));
            }
            per_vertex[v as usize].push((bone, w));
        }
    }
    if let Some(v) = per_vertex.iter().position(|l| l.iter().map(|(_, w)| w).sum::<f64>() <= 0.0) {
        return Err(bad(format!("vertex {v} has no weight")));
    }
    Ok(SkinWeights::normalised(per_vertex))
}
