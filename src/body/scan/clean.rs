//! Validation and cleaning of a freshly read scan: what a scanner gets wrong, found and either
//! rejected (an error) or repaired and reported (a warning).
//!
//! - non-finite coordinates: error (the file is corrupt);
//! - bit-identical vertices: welded (STL repeats corners; OBJ groups split shared vertices);
//! - degenerate triangles (a repeated corner, or flat: no area up to rounding, measured
//!   against the triangle's own size, so no other vertex can change the verdict): dropped;
//! - several connected components: the largest by area is the body; floor patches, props and
//!   noise islands are dropped and listed; so are vertices no triangle uses (silently);
//!
//! Holes, non-manifold edges and vertices are a diagnosis, not a repair: see
//! [`crate::body::mesh::topology`] and [`Topology::warnings`](crate::body::mesh::topology::Topology::warnings).

use crate::body::mesh::{Aabb, Mesh, components};
use crate::messages::number;
use glam::DVec3;
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
    #[serde(serialize_with = "crate::body::scan::serialize_aabb")]
    pub bounds: Aabb,
}

/// A scan that cannot be used.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum CleanError {
    /// A vertex with NaN or infinite coordinates.
    #[error("vertex {vertex} has a non-finite coordinate ({}, {}, {})", number(*x), number(*y), number(*z))]
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
    if mesh.positions.par_iter().any(|p| !p.is_finite()) {
        let vertex = mesh.positions.iter().position(|p| !p.is_finite()).unwrap_or(0);
        let p = mesh.positions[vertex];
        return Err(CleanError::NonFinite { vertex, x: p.x, y: p.y, z: p.z });
    }
    let welded_vertices = mesh.weld_identical();

    let degenerate = |t: usize| {
        let [a, b, c] = mesh.triangles[t];
        a == b || b == c || a == c || is_flat(mesh.corners(t))
    };
    let dropped: Vec<usize> =
        (0..mesh.triangles.len()).into_par_iter().filter(|&t| degenerate(t)).collect();
    let degenerate_triangles = dropped.len();
    if degenerate_triangles > 0 {
        let mut drop = dropped.into_iter().peekable();
        mesh.retain_triangles(|t| drop.next_if_eq(&t).is_none());
    }
    if mesh.triangles.is_empty() {
        return Err(CleanError::AllDegenerate);
    }

    let found = components(&mesh);
    let total: f64 = found.parts.iter().map(|c| c.area).sum();
    let dropped_components = found
        .parts
        .iter()
        .skip(1)
        .map(|c| DroppedComponent {
            triangles: c.triangles,
            area_fraction: c.area / total,
            bounds: c.bounds,
        })
        .collect();
    if !found.is_one_piece() {
        let body: Vec<bool> =
            mesh.triangles.par_iter().map(|t| found.of_vertex[t[0] as usize] == 0).collect();
        mesh.retain_triangles(|t| body[t]);
    }
    let report = CleaningReport {
        welded_vertices,
        degenerate_triangles,
        components: found.count,
        dropped_components,
    };
    Ok((mesh, report))
}

/// Whether a triangle is flat: its area is within rounding of zero for its size (twice the
/// area at most 1e-12 of its longest edge squared).
fn is_flat([a, b, c]: [DVec3; 3]) -> bool {
    let longest =
        (b - a).length_squared().max((c - b).length_squared()).max((a - c).length_squared());
    (b - a).cross(c - a).length() <= 1e-12 * longest
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::body::mesh::shapes::add_tetrahedron as tetrahedron;

    #[test]
    fn keeps_the_largest_piece_and_drops_islands_degenerates_and_unused_vertices() {
        let mut mesh = Mesh::default();
        tetrahedron(&mut mesh, DVec3::ZERO, 1.0); // an island
        mesh.positions.push(DVec3::splat(9.0)); // used by no triangle
        tetrahedron(&mut mesh, DVec3::new(3.0, 0.0, 0.0), 10.0); // the body
        mesh.triangles.push([5, 5, 6]); // degenerate
        let (body, report) = clean(mesh).expect("cleans");
        assert_eq!(body.triangles.len(), 4);
        assert_eq!(body.positions.len(), 4);
        assert_eq!(body.positions[0], DVec3::new(3.0, 0.0, 0.0));
        assert_eq!(report.degenerate_triangles, 1);
        assert_eq!(report.components, 2);
        assert_eq!(report.dropped_components.len(), 1);
        assert_eq!(report.dropped_components[0].triangles, 4);
        assert!((report.dropped_components[0].area_fraction - 1.0 / 101.0).abs() < 1e-12);
    }

    #[test]
    fn flat_triangles_are_degenerate_whatever_else_is_in_the_scan() {
        let mut mesh = Mesh::default();
        tetrahedron(&mut mesh, DVec3::ZERO, 100.0);
        // Collinear corners; a far vertex no triangle uses does not change anything.
        mesh.positions.extend([DVec3::new(0.0, 0.0, 300.0), DVec3::new(0.0, 0.0, 200.0)]);
        mesh.triangles.push([3, 4, 5]);
        mesh.positions.push(DVec3::splat(1e10));
        let (body, report) = clean(mesh).expect("cleans");
        assert_eq!(report.degenerate_triangles, 1);
        assert_eq!(body.triangles.len(), 4);
        assert_eq!(body.positions.len(), 4);
        // A tiny but well-shaped triangle is not flat.
        assert!(!is_flat([DVec3::ZERO, DVec3::X * 1e-9, DVec3::Y * 1e-9]));
        assert!(is_flat([DVec3::ZERO, DVec3::X, DVec3::X * 2.0]));
    }

    #[test]
    fn a_clean_body_is_left_as_it_is() {
        let mut mesh = Mesh::default();
        tetrahedron(&mut mesh, DVec3::ZERO, 2.0);
        let (body, report) = clean(mesh.clone()).expect("cleans");
        assert_eq!(body, mesh);
        assert!(report.warnings().is_empty());
    }

    #[test]
    fn a_non_finite_vertex_is_an_error_naming_it() {
        let mut mesh = Mesh::default();
        tetrahedron(&mut mesh, DVec3::ZERO, 1.0);
        mesh.positions[2].y = f64::NAN;
        let err = clean(mesh).expect_err("rejected");
        assert!(matches!(err, CleanError::NonFinite { vertex: 2, .. }), "{err}");
    }
}
