//! The prologue of every command that reads a scan: load it, gather what the reader's cleaning
//! and the topology check warn about, and denoise it (not a mannequin dressform made, which
//! has no scanner noise).

use super::frame::FrameOptions;
use super::{Scan, ScanError, load};
use crate::body::mesh::decimate::decimate;
use crate::body::mesh::{Mesh, Topology, topology};
use std::path::Path;

/// How a command reads and prepares its scan.
#[derive(Debug, Clone, Default)]
pub struct ScanOptions {
    /// The scan's frame, where the user gave it (detected otherwise).
    pub frame: FrameOptions,
    /// Taubin smoothing passes ([`crate::body::mesh::Mesh::taubin_smooth`]), 0 for none; never
    /// applied to a mannequin dressform made ([`Scan::carried`]).
    pub smooth: usize,
    /// The most triangles to work on: a denser scan is decimated to this many after reading
    /// ([`decimate`]; the commands that build a mannequin ask for
    /// [`crate::body::mesh::decimate::WORKING_TRIANGLES`]); `None` keeps every triangle (`info`,
    /// `slice`, `measure` report the scan as it is).
    pub max_triangles: Option<usize>,
}

/// A scan read and prepared for a command.
#[derive(Debug, Clone)]
pub struct PreparedScan {
    /// The scan, in the canonical frame, smoothed where [`Self::smoothed`] says.
    pub scan: Scan,
    /// What the reader's cleaning found, then what the topology check found (holes,
    /// manifoldness, orientation), then which units were read where another would also make
    /// a person: always in that order.
    pub warnings: Vec<String>,
    /// Whether the body was smoothed (passes asked for, and not a mannequin dressform made).
    pub smoothed: bool,
}

/// Reads the scan at `path` in the frame `options` give, gathers its warnings and smooths
/// it (see [`PreparedScan::new`]).
pub fn prepare(path: &Path, options: &ScanOptions) -> Result<PreparedScan, ScanError> {
    Ok(prepare_then(path, options, |_, check| ((), check.run()))?.0)
}

/// [`prepare`], then `work` on the prepared scan, which runs its topology check (see
/// [`PreparedScan::reduced_then`]).
pub fn prepare_then<R: Send>(
    path: &Path,
    options: &ScanOptions,
    work: impl FnOnce(&Scan, TopologyCheck) -> (R, Topology) + Send,
) -> Result<(PreparedScan, R), ScanError> {
    let scan = load(path, &options.frame)?;
    Ok(PreparedScan::reduced_then(scan, options.smooth, options.max_triangles, work))
}

impl PreparedScan {
    /// `scan` (already read) with its warnings gathered (the cleaning's, then the topology's),
    /// and smoothed with `passes` Taubin passes unless it is a mannequin dressform made: that
    /// has no scanner noise, and is measured as it is, at the levels its file carries.
    pub fn new(scan: Scan, passes: usize) -> PreparedScan {
        PreparedScan::reduced(scan, passes, None)
    }

    /// [`Self::new`], the scan decimated to at most `max_triangles` between its warnings (which
    /// describe the scan as read) and the smoothing; a note says so.
    pub fn reduced(scan: Scan, passes: usize, max_triangles: Option<usize>) -> PreparedScan {
        Self::reduced_then(scan, passes, max_triangles, |_, check| ((), check.run())).0
    }

    /// [`Self::reduced`], then `work` on the prepared scan. The topology check (holes,
    /// manifoldness, orientation: only a warning, and a pass over every vertex's fan) runs
    /// beside the next step that reads the same triangles: the decimation where the scan is
    /// decimated (the scan as read is then dropped before `work`), otherwise `work`, which is
    /// handed the check to run beside whichever of its steps leaves cores idle (smoothing
    /// moves vertices, never triangles, so the smoothed scan's topology is the scan's as read).
    pub fn reduced_then<R: Send>(
        mut scan: Scan,
        passes: usize,
        max_triangles: Option<usize>,
        work: impl FnOnce(&Scan, TopologyCheck) -> (R, Topology) + Send,
    ) -> (PreparedScan, R) {
        let (checked, decimated) = match max_triangles {
            Some(max) if scan.body.triangles.len() > max => {
                let (t, d) = rayon::join(|| topology(&scan.body), || decimate(&scan.body, max));
                (Some(t), d)
            }
            _ => (None, None),
        };
        let mut note = None;
        if let Some((body, d)) = decimated {
            scan.body = body;
            note = Some(format!(
                "{} triangles, more than the pipeline needs: decimated to {} (largest deviation \
                 {:.1} mm)",
                d.from_triangles, d.to_triangles, d.error
            ));
        }
        let smoothed = passes > 0 && scan.carried.is_none();
        if smoothed {
            scan.body.taubin_smooth(passes);
        }
        let check = match checked {
            Some(t) => TopologyCheck::Done(t),
            None => TopologyCheck::Pending(&scan.body),
        };
        let (out, checked) = work(&scan, check);
        let mut warnings = scan.cleaning.warnings();
        warnings.extend(checked.warnings());
        warnings.extend(scan.frame.units_warning());
        warnings.extend(note);
        (PreparedScan { scan, warnings, smoothed }, out)
    }
}

/// The topology check of a prepared scan: done already (beside the decimation), or to run on
/// the body, which [`PreparedScan::reduced_then`] hands its work to run where it fits.
pub enum TopologyCheck<'a> {
    /// The check's result.
    Done(Topology),
    /// The body still to check.
    Pending(&'a Mesh),
}

impl TopologyCheck<'_> {
    /// The check's result, running it if it is still to run.
    pub fn run(self) -> Topology {
        match self {
            TopologyCheck::Done(t) => t,
            TopologyCheck::Pending(body) => topology(body),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::body::mesh::Mesh;
    use crate::body::mesh::shapes::add_tetrahedron;
    use crate::body::scan::frame::{FileFrame, Units};
    use glam::DVec3;

    /// `mesh` as a scan, cleaned and in the frame of its own coordinates (mm, Z up).
    fn scan_of(mesh: Mesh) -> Scan {
        let identity = FileFrame {
            units: Units::Mm,
            rotation: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
            translation: [0.0; 3],
        };
        let stated = super::super::Placing::Stated(&identity);
        super::super::cleaned_and_placed(mesh, Path::new("test.obj"), stated)
            .expect("a tetrahedron cleans")
    }

    /// A tetrahedron: closed, smoothing moves its corners.
    fn tetrahedron() -> Mesh {
        let mut mesh = Mesh::default();
        add_tetrahedron(&mut mesh, DVec3::ZERO, 100.0);
        mesh
    }

    #[test]
    fn warnings_come_from_the_reader_first_then_from_the_topology() {
        let mut mesh = Mesh::default();
        add_tetrahedron(&mut mesh, DVec3::new(500.0, 0.0, 0.0), 1.0); // an island
        add_tetrahedron(&mut mesh, DVec3::ZERO, 100.0); // the body
        mesh.triangles.pop(); // a hole in the body
        mesh.triangles.push([4, 4, 5]); // degenerate
        let prepared = PreparedScan::new(scan_of(mesh), 0);
        let w = &prepared.warnings;
        assert_eq!(w.len(), 3, "{w:?}");
        assert!(w[0].contains("degenerate"), "{w:?}");
        assert!(w[1].contains("connected components"), "{w:?}");
        assert!(w[2].contains("1 hole"), "{w:?}");
        assert!(!prepared.smoothed);
    }

    #[test]
    fn a_scan_is_smoothed_and_a_mannequin_dressform_made_is_not() {
        let before = tetrahedron().positions;
        let scan = PreparedScan::new(scan_of(tetrahedron()), 8);
        assert!(scan.smoothed && scan.warnings.is_empty(), "{:?}", scan.warnings);
        assert_ne!(scan.scan.body.positions, before);

        let mut mannequin = scan_of(tetrahedron());
        mannequin.carried = Some(crate::body::scan::carried::tests::body());
        let mannequin = PreparedScan::new(mannequin, 8);
        assert!(!mannequin.smoothed);
        assert_eq!(mannequin.scan.body.positions, before);
    }

    #[test]
    fn no_passes_no_smoothing() {
        let before = tetrahedron().positions;
        let scan = PreparedScan::new(scan_of(tetrahedron()), 0);
        assert!(!scan.smoothed);
        assert_eq!(scan.scan.body.positions, before);
    }
}
