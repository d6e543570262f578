//! Horizontal cross-sections of a mesh: many parallel planes in one pass.
//!
//! - [`sections`] cuts a mesh at a sorted list of heights and returns each height's closed
//!   loops ([`Section`]);
//! - [`Contour`] measures one loop: contour perimeter, tape girth (the convex hull's perimeter:
//!   a tape bridges concavities), area, centroid.
//!
//! Robustness: a vertex lying exactly on a plane counts as above it (a symbolic perturbation),
//! so every crossing triangle yields exactly one segment and loops close exactly; loop points
//! are chained by the identity of the mesh edge they lie on, never by comparing coordinates.
//! Loops left open by holes in the scan are closed by pairing loose ends, and reported.

mod contour;
mod sweep;

pub use contour::{Contour, convex_hull};
pub use sweep::sections;

/// The loops of one horizontal plane.
#[derive(Debug, Clone, PartialEq)]
pub struct Section {
    /// Height of the plane (z, in the mesh's units).
    pub height: f64,
    /// Closed loops, largest area first.
    pub loops: Vec<Contour>,
    /// Open chains that had to be closed (scan holes crossing this plane).
    pub bridged_gaps: usize,
}
