//! The scanned body as geometry: the mesh, reading and cleaning a scan into the canonical
//! frame, slicing it, finding its regions and landmarks, and the segmented body every later
//! stage takes.

pub mod mesh;
pub mod regions;
pub mod scan;
pub mod segmented_body;
pub mod slice;
