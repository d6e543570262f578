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

use super::frame::{Survey, SurveyBlock, Surveyor};
use crate::body::mesh::{Aabb, Mesh, components, reduce};
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
pub fn clean(mesh: Mesh) -> Result<(Mesh, CleaningReport), CleanError> {
    cleaned(mesh, false).map(|(body, report, _)| (body, report))
}

/// [`clean`], taking the canonical frame's [`Survey`] of the body in the same pass as the
/// search for flat triangles, which measures each triangle's area anyway (one pass over the
/// triangles' corners instead of two). The pass sees the welded mesh, so the survey is the
/// body's only when the cleaning drops no triangle (the usual scan); `None` otherwise.
pub fn clean_surveyed(mesh: Mesh) -> Result<(Mesh, CleaningReport, Option<Survey>), CleanError> {
    cleaned(mesh, true)
}

/// [`clean`], with the survey when `survey` is asked for (see [`clean_surveyed`]).
fn cleaned(
    mut mesh: Mesh,
    survey: bool,
) -> Result<(Mesh, CleaningReport, Option<Survey>), CleanError> {
    if mesh.positions.par_iter().any(|p| !p.is_finite()) {
        let vertex = mesh.positions.iter().position(|p| !p.is_finite()).unwrap_or(0);
        let p = mesh.positions[vertex];
        return Err(CleanError::NonFinite { vertex, x: p.x, y: p.y, z: p.z });
    }
    let welded_vertices = mesh.weld_identical();

    let surveyor = survey.then(|| Surveyor::new(&mesh));
    // Per block of triangles, in order: the degenerate ones, and the block's survey.
    let blocks = reduce::blocks(mesh.triangles.len(), |range| {
        let mut dropped = Vec::new();
        let mut block = SurveyBlock::default();
        for t in range {
            let corners = mesh.corners(t);
            let [a, b, c] = corners;
            // Twice the area, and the centroid, as the frame's survey computes them.
            let twice_area = (b - a).cross(c - a).length();
            let [i, j, k] = mesh.triangles[t];
            if i == j || j == k || i == k || is_flat(corners, twice_area) {
                dropped.push(t);
            }
            if let Some(surveyor) = &surveyor {
                surveyor.add(&mut block, (a + b + c) / 3.0, 0.5 * twice_area);
            }
        }
        (dropped, block)
    });
    let (dropped, survey): (Vec<Vec<usize>>, Vec<SurveyBlock>) = blocks.into_iter().unzip();
    let dropped = dropped.concat();
    let degenerate_triangles = dropped.len();
    let mut survey = surveyor.map(|surveyor| surveyor.finish(survey));
    if degenerate_triangles > 0 {
        let mut drop = dropped.into_iter().peekable();
        mesh.retain_triangles(|t| drop.next_if_eq(&t).is_none());
        survey = None;
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
        survey = None;
    }
    let report = CleaningReport {
        welded_vertices,
        degenerate_triangles,
        components: found.count,
        dropped_components,
    };
    Ok((mesh, report, survey))
}

/// Whether a triangle (its corners, and twice its area) is flat: its area is within rounding
/// of zero for its size (twice the area at most 1e-12 of its longest edge squared).
fn is_flat([a, b, c]: [DVec3; 3], twice_area: f64) -> bool {
    let longest =
        (b - a).length_squared().max((c - b).length_squared()).max((a - c).length_squared());
    twice_area <= 1e-12 * longest
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
        let flat = |[a, b, c]: [DVec3; 3]| is_flat([a, b, c], (b - a).cross(c - a).length());
        assert!(!flat([DVec3::ZERO, DVec3::X * 1e-9, DVec3::Y * 1e-9]));
        assert!(flat([DVec3::ZERO, DVec3::X, DVec3::X * 2.0]));
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
