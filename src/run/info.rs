//! The `dressform info` report on a scan: what was read, what cleaning did, the frame found,
//! and the body's size and topology. Serialised as the documented `--json` output.

use crate::body::mesh::{Aabb, topology};
use crate::body::scan::Scan;
use crate::body::scan::clean::DroppedComponent;
use crate::body::scan::frame::{Direction, Units};
use serde::Serialize;
use std::fmt;

/// Everything `dressform info` reports (its JSON layout: docs/formats.md, `dressform info --json`).
#[derive(Debug, Clone, Serialize)]
pub struct ScanInfo {
    /// The file.
    pub file: String,
    /// Vertices as read.
    pub vertices: usize,
    /// Triangles as read (polygons triangulated).
    pub triangles: usize,
    /// The scan's frame.
    pub frame: FrameInfo,
    /// The body that was kept.
    pub body: BodyInfo,
    /// Connected components.
    pub components: ComponentsInfo,
    /// Repairs made while cleaning.
    pub cleaning: CleaningInfo,
    /// Warnings, as printed.
    pub warnings: Vec<String>,
}

/// The scan's units and orientation.
#[derive(Debug, Clone, Serialize)]
pub struct FrameInfo {
    /// Length unit of the file.
    pub units: Units,
    /// `true` when detected from the height, `false` when given.
    pub units_detected: bool,
    /// Up direction in the file (`+y`, `+z`, ...).
    pub up: Direction,
    /// `true` when detected.
    pub up_detected: bool,
    /// The direction the subject faces, in the file's frame (unit vector).
    pub facing: [f64; 3],
    /// `facing` as an axis name when within 1 degree of one, else `null`.
    pub facing_axis: Option<Direction>,
    /// `true` when detected.
    pub facing_detected: bool,
    /// How far the feet reach in front of the shins, in mm (near 0: front and back unclear).
    pub facing_evidence_mm: f64,
    /// `true` when the file's header states the frame (a mannequin dressform wrote): nothing
    /// was detected, and heights are from the floor of the scan it was made from.
    pub from_header: bool,
}

/// The kept body, in the canonical frame (mm, Z up, floor at 0, +X left, facing -Y).
#[derive(Debug, Clone, Serialize)]
pub struct BodyInfo {
    /// Vertices after cleaning.
    pub vertices: usize,
    /// Triangles after cleaning.
    pub triangles: usize,
    /// Height in mm.
    pub height_mm: f64,
    /// Bounding box in the canonical frame, mm.
    #[serde(serialize_with = "crate::body::scan::serialize_aabb")]
    pub bounding_box_mm: Aabb,
    /// Surface area in m².
    pub area_m2: f64,
    /// No holes.
    pub closed: bool,
    /// Holes (boundary loops).
    pub holes: usize,
    /// No non-manifold edges or vertices.
    pub manifold: bool,
    /// Edges shared by more than two triangles.
    pub non_manifold_edges: usize,
    /// Vertices where separate fans of triangles touch.
    pub non_manifold_vertices: usize,
    /// Neighbouring triangles agree on orientation.
    pub consistently_oriented: bool,
}

/// The connected components of the scan.
#[derive(Debug, Clone, Serialize)]
pub struct ComponentsInfo {
    /// How many there were.
    pub count: usize,
    /// The ones dropped (not the body), largest first; boxes in the file's coordinates.
    pub dropped: Vec<DroppedComponent>,
}

/// Repairs.
#[derive(Debug, Clone, Serialize)]
pub struct CleaningInfo {
    /// Bit-identical vertices merged.
    pub welded_vertices: usize,
    /// Zero-area triangles dropped.
    pub degenerate_triangles: usize,
}

impl ScanInfo {
    /// The report on `scan`.
    pub fn new(scan: &Scan) -> Self {
        let t = &topology(&scan.body);
        let body = &scan.body;
        let frame = &scan.frame;
        ScanInfo {
            file: scan.source.display().to_string(),
            vertices: scan.raw_vertices,
            triangles: scan.raw_triangles,
            frame: FrameInfo {
                units: frame.units,
                units_detected: frame.units_detected,
                up: frame.up,
                up_detected: frame.up_detected,
                facing: frame.facing.to_array(),
                facing_axis: frame.facing_axis(),
                facing_detected: frame.facing_detected,
                facing_evidence_mm: frame.facing_evidence_mm,
                from_header: frame.from_header,
            },
            body: BodyInfo {
                vertices: body.positions.len(),
                triangles: body.triangles.len(),
                height_mm: frame.height_mm,
                bounding_box_mm: body.bounds().expect("a cleaned body has triangles"),
                area_m2: body.area() * 1e-6,
                closed: t.is_closed(),
                holes: t.boundary_loops.len(),
                manifold: t.is_manifold(),
                non_manifold_edges: t.non_manifold_edges,
                non_manifold_vertices: t.non_manifold_vertices,
                consistently_oriented: t.is_consistently_oriented(),
            },
            components: ComponentsInfo {
                count: scan.cleaning.components,
                dropped: scan.cleaning.dropped_components.clone(),
            },
            cleaning: CleaningInfo {
                welded_vertices: scan.cleaning.welded_vertices,
                degenerate_triangles: scan.cleaning.degenerate_triangles,
            },
            warnings: scan
                .cleaning
                .warnings()
                .into_iter()
                .chain(t.warnings())
                .chain(frame.units_warning())
                .collect(),
        }
    }
}

impl fmt::Display for ScanInfo {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let fr = &self.frame;
        let b = &self.body;
        let how = |detected: bool| match (detected, fr.from_header) {
            (true, _) => "detected",
            (false, true) => "from the file's header",
            (false, false) => "given",
        };
        let facing = match fr.facing_axis {
            Some(axis) => axis.to_string(),
            None => format!("({:.3}, {:.3}, {:.3})", fr.facing[0], fr.facing[1], fr.facing[2]),
        };
        writeln!(f, "{}", self.file)?;
        writeln!(f, "  read        {} vertices, {} triangles", self.vertices, self.triangles)?;
        writeln!(f, "  units       {} ({})", fr.units, how(fr.units_detected))?;
        writeln!(f, "  up          {} ({})", fr.up, how(fr.up_detected))?;
        if fr.from_header {
            writeln!(f, "  facing      {facing} ({})", how(false))?;
        } else {
            writeln!(
                f,
                "  facing      {facing} ({}; feet {:.0} mm ahead of the shins)",
                how(fr.facing_detected),
                fr.facing_evidence_mm
            )?;
        }
        writeln!(f, "  height      {:.1} mm", b.height_mm)?;
        let (lo, hi) = (b.bounding_box_mm.min, b.bounding_box_mm.max);
        writeln!(
            f,
            "  bounds      x {:.1}..{:.1}  y {:.1}..{:.1}  z {:.1}..{:.1} mm (canonical: +X left, facing -Y, Z up)",
            lo.x, hi.x, lo.y, hi.y, lo.z, hi.z
        )?;
        writeln!(
            f,
            "  body        {} vertices, {} triangles, {:.3} m²",
            b.vertices, b.triangles, b.area_m2
        )?;
        writeln!(
            f,
            "  components  {} ({} dropped)",
            self.components.count,
            self.components.dropped.len()
        )?;
        writeln!(f, "  holes       {}", b.holes)?;
        writeln!(
            f,
            "  manifold    {} ({} non-manifold edges, {} non-manifold vertices); {}",
            if b.manifold { "yes" } else { "no" },
            b.non_manifold_edges,
            b.non_manifold_vertices,
            if b.consistently_oriented {
                "consistently oriented"
            } else {
                "orientation inconsistent"
            }
        )?;
        for w in &self.warnings {
            writeln!(f, "  warning     {w}")?;
        }
        Ok(())
    }
}
