//! Validation and cleaning of a freshly read scan: what a scanner gets wrong, found and either
//! rejected (an error) or repaired and reported (a warning).
//!
//! - non-finite coordinates: error (the file is corrupt);
//! - bit-identical vertices: welded (STL repeats corners; OBJ groups split shared vertices);
//! - degenerate triangles (repeated corner, zero area): dropped;
//! - several connected components: the largest by area is the body; floor patches, props and
//!   noise islands are dropped and listed;
//!
//! Holes, non-manifold edges and vertices are a diagnosis, not a repair: see
//! [`crate::mesh::topology`] and [`Topology::warnings`].

use crate::mesh::{Aabb, Mesh, components};
use rayon::prelude::*;
use serde::Serialize;

/// What cleaning found and did.
#[derive(Debug, Clone, Serialize)]
pub struct CleaningReport {
    /// Vertices merged into an identical one.
    pub welded_vertices: usize,
    /// Triangles dropped because two corners coincide or the area is zero.
    pub degenerate_triangles: usize,
    /// Connected components found (before dropping).
    pub components: usize,
    /// The components dropped, largest first.
    pub dropped_components: Vec<DroppedComponent>,
}

/// A connected piece that is not the body.
#[derive(Debug, Clone, Serialize)]
pub struct DroppedComponent {
    /// Its triangle count.
    pub triangles: usize,
    /// Its share of the whole scan's surface area.
    pub area_fraction: f64,
    /// Its bounding box, in the file's coordinates.
    #[serde(serialize_with = "crate::scan::serialize_aabb")]
    pub bounds: Aabb,
}

/// A scan that cannot be used.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum CleanError {
    /// A vertex with NaN or infinite coordinates.
    #[error("vertex {vertex} has a non-finite coordinate ({x}, {y}, {z})")]
    NonFinite {
        /// Vertex number (0-based, file order).
        vertex: usize,
        /// Its coordinates as read.
        x: f64,
        /// Its coordinates as read.
        y: f64,
        /// Its coordinates as read.
        z: f64,
    },
    /// Nothing left after dropping degenerate triangles.
    #[error("every face is degenerate (zero area)")]
    AllDegenerate,
}

impl CleaningReport {
    /// Human-readable warnings, one per finding worth a user's attention.
    pub fn warnings(&self) -> Vec<String> {
        let mut w = Vec::new();
        if self.degenerate_triangles > 0 {
            w.push(format!(
                "dropped {} degenerate (zero-area) triangles",
                self.degenerate_triangles
            ));
        }
        if !self.dropped_components.is_empty() {
            let triangles: usize = self.dropped_components.iter().map(|c| c.triangles).sum();
            let share: f64 = self.dropped_components.iter().map(|c| c.area_fraction).sum();
            w.push(format!(
                "kept the largest of {} connected components as the body; dropped {} others \
                 ({triangles} triangles, {:.2}% of the surface: floor patches, props or noise)",
                self.components,
                self.dropped_components.len(),
                100.0 * share
            ));
        }
        w
    }
}

/// Validates `mesh` and reduces it to the body: see the module documentation.
pub fn clean(mut mesh: Mesh) -> Result<(Mesh, CleaningReport), CleanError> {
    if let Some((vertex, p)) = mesh.positions.iter().enumerate().find(|(_, p)| !p.is_finite()) {
        return Err(CleanError::NonFinite { vertex, x: p.x, y: p.y, z: p.z });
    }
    let welded_vertices = mesh.weld_identical();

    let before = mesh.triangles.len();
    let scale = mesh.bounds().map_or(0.0, |b| b.size().length_squared());
    let keep: Vec<bool> = (0..mesh.triangles.len())
        .into_par_iter()
        .map(|t| {
            let [a, b, c] = mesh.triangles[t];
            a != b && b != c && a != c && mesh.triangle_area(t) > scale * 1e-16
        })
        .collect();
    mesh.retain_triangles(|t| keep[t]);
    let degenerate_triangles = before - mesh.triangles.len();
    if mesh.triangles.is_empty() {
        return Err(CleanError::AllDegenerate);
    }

    let found = components(&mesh);
    let total: f64 = found.parts.iter().map(|c| c.area).sum();
    let dropped_components = found.parts[1..]
        .iter()
        .map(|c| DroppedComponent {
            triangles: c.triangles,
            area_fraction: c.area / total,
            bounds: c.bounds,
        })
        .collect();
    if found.parts.len() > 1 {
        mesh.retain_triangles(|t| found.of_triangle[t] == 0);
    }
    let report = CleaningReport {
        welded_vertices,
        degenerate_triangles,
        components: found.parts.len(),
        dropped_components,
    };
    Ok((mesh, report))
}
