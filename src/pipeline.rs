//! The scan-to-mannequin pipeline as one call: segment, build the symmetric mannequin,
//! measure both. Used by `symmetrize`, and by `run` and `demo`.

use crate::mannequin::{self, Mannequin, MannequinError, MannequinOptions};
use crate::measure::{Comparison, compare, levels};
use crate::regions::{BodyRegions, TRACKING_STEP_MM};
use crate::scan::Scan;
use crate::scan::carried::CarriedBody;
use crate::scan::format::Export;
use crate::scan::frame::CanonicalFrame;

/// A scan's symmetric mannequin with its segmentation and measurements.
#[derive(Debug, Clone)]
pub struct Symmetrized {
    /// The input body's regions and landmarks.
    pub regions: BodyRegions,
    /// The mannequin.
    pub mannequin: Mannequin,
    /// Table 1 and Fig. 11.
    pub comparison: Comparison,
}

impl Symmetrized {
    /// The mannequin's file as `export` describes it, with the header line that lets
    /// dressform read it back as a body ([`CarriedBody`]: frame, own landmarks, levels).
    /// An export of coordinates as they are ([`crate::scan::format::Placement::AsIs`]) writes the mannequin in the
    /// frame of the scan it was made from, `scan`.
    pub fn mannequin_file(&self, export: &Export, scan: &CanonicalFrame) -> Vec<u8> {
        let (mesh, frame) = export.place(&self.mannequin.mesh, scan);
        let carried = CarriedBody {
            frame,
            landmarks: self.mannequin.own_landmarks(),
            levels: self.comparison.levels,
        };
        export.clone().with_comments([carried.header_line()]).encode(&mesh)
    }
}

/// The steps of [`symmetrize`], reported to `progress` as they start.
pub const STEPS: [&str; 3] =
    ["segmenting the body", "building the symmetric mannequin", "measuring"];

/// Builds the symmetric mannequin of `scan`, calling `progress(step)` before each step.
pub fn symmetrize(
    scan: &Scan,
    options: &MannequinOptions,
    mut progress: impl FnMut(usize),
) -> Result<Symmetrized, MannequinError> {
    progress(0);
    let regions = BodyRegions::find(&scan.body, TRACKING_STEP_MM)?;
    progress(1);
    let levels = levels(&scan.body, &regions);
    let mannequin =
        mannequin::build(&scan.body, &regions, &[levels.chest, levels.waist, levels.hip], options)?;
    progress(2);
    let comparison = compare(&scan.body, &regions, &levels, &mannequin);
    Ok(Symmetrized { regions, mannequin, comparison })
}
