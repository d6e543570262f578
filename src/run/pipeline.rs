//! The pipeline as one call per command: [`symmetrize`] (segment the scan, build the
//! symmetric mannequin, measure both, take its profiles) for `symmetrize`; [`shape`] (that,
//! then the form fitted to the mannequin and its set-points) for `run` and `demo`, which
//! drive the form to the result. [`crate::run::outputs`] turns a result into its files.

use std::collections::BTreeMap;

use form_description::FormDescription;

use crate::body::regions::{BodyRegions, Region};
use crate::body::scan::Scan;
use crate::body::scan::carried::CarriedBody;
use crate::body::scan::format::Export;
use crate::body::scan::frame::CanonicalFrame;
use crate::body::segmented_body::SegmentedBody;
use crate::form::form_fit::{self, FormFit, FormFitError, region_of, regions_of};
use crate::form::setpoints::SetPoints;
use crate::shape::mannequin::{self, Mannequin, MannequinError, MannequinOptions, StopAt};
use crate::shape::measure::{Comparison, compare, levels};
use crate::shape::profiles::Profiles;

/// A scan's symmetric mannequin with its segmentation, measurements and profiles.
#[derive(Debug, Clone)]
pub struct Symmetrized {
    /// The input body's regions and landmarks.
    pub regions: BodyRegions,
    /// The mannequin.
    pub mannequin: Mannequin,
    /// Table 1 and Fig. 11.
    pub comparison: Comparison,
    /// The mannequin's sections as `profiles.json` states them (what the form is fitted to).
    pub profiles: Profiles,
}

impl Symmetrized {
    /// The mannequin's file as `export` describes it, with the header line that lets
    /// dressform read it back as a body ([`CarriedBody`]: frame, own landmarks, levels).
    /// An export of coordinates as they are ([`crate::body::scan::format::Placement::AsIs`]) writes the mannequin in the
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
    let body = SegmentedBody::find(&scan.body)?;
    symmetrize_segmented(&body, options, progress)
}

/// [`symmetrize`] from the segmented body on: the steps after the first.
fn symmetrize_segmented(
    body: &SegmentedBody,
    options: &MannequinOptions,
    mut progress: impl FnMut(usize),
) -> Result<Symmetrized, MannequinError> {
    progress(1);
    let levels = levels(body);
    let mannequin = mannequin::build(body, &[levels.chest, levels.waist, levels.hip], options)?;
    progress(2);
    let comparison = compare(body, &levels, &mannequin);
    let profiles = Profiles::of(&mannequin, &comparison.levels);
    Ok(Symmetrized { regions: body.regions().clone(), mannequin, comparison, profiles })
}

/// A scan's mannequin with a form fitted to it: what `run` and `demo` drive the form to.
#[derive(Debug, Clone)]
pub struct Shaped {
    /// The mannequin, its measurements and profiles.
    pub symmetrized: Symmetrized,
    /// Where each of the form's rings shapes the mannequin, and how well.
    pub fit: FormFit,
    /// The fit's set-points, with each ring's target girth.
    pub setpoints: SetPoints,
    /// Each ring's girths along the chain, in the form's order.
    pub rings: Vec<RingGirths>,
}

/// One ring's girths along the chain, where the ring shapes the body.
#[derive(Debug, Clone, PartialEq)]
pub struct RingGirths {
    /// The ring.
    pub ring: String,
    /// The body height it shapes, mm.
    pub body_z_mm: f64,
    /// The scan's tape girth there (the section of the ring's region), mm; `None` where the
    /// scan has no such section.
    pub scan_mm: Option<f64>,
    /// The mannequin's tape girth there, mm (0 where the mannequin has no section).
    pub mannequin_mm: f64,
}

/// Why [`shape`] failed.
#[derive(Debug, thiserror::Error)]
pub enum ShapeError {
    /// The mannequin could not be built.
    #[error(transparent)]
    Mannequin(#[from] MannequinError),
    /// The form could not be fitted to it.
    #[error(transparent)]
    Fit(#[from] FormFitError),
    /// A ring of the form shapes the legs below where the mannequin's end
    /// ([`MannequinOptions::stop_at`]): it would stay retracted.
    #[error(
        "the form's ring {ring} shapes the legs at z = {z:.0} mm, below the mannequin's, which end at {end:.0} mm (--stop-at {stop}): build the mannequin with whole legs"
    )]
    BelowTheLegs {
        /// The ring.
        ring: String,
        /// The mannequin height it shapes (mm).
        z: f64,
        /// The height of the legs' lowest layer (mm).
        end: f64,
        /// Where the legs were asked to end.
        stop: &'static str,
    },
}

/// The steps of [`shape`]: those of [`symmetrize`], then the fit.
pub const SHAPE_STEPS: [&str; 4] = [STEPS[0], STEPS[1], STEPS[2], "fitting the form"];

/// Builds the symmetric mannequin of `scan` and fits `form` to it, calling `progress(step)`
/// before each of [`SHAPE_STEPS`].
pub fn shape(
    scan: &Scan,
    options: &MannequinOptions,
    form: &FormDescription,
    mut progress: impl FnMut(usize),
) -> Result<Shaped, ShapeError> {
    progress(0);
    let body = SegmentedBody::find(&scan.body).map_err(MannequinError::from)?;
    let symmetrized = symmetrize_segmented(&body, options, &mut progress)?;
    progress(STEPS.len());
    let fit = form_fit::fit(&symmetrized.profiles, form)?;
    if let Some(stop) = options.stop_at {
        check_legs_reach(&symmetrized.mannequin, form, &fit, stop)?;
    }
    let setpoints = fit.setpoints();
    let rings = ring_girths(&body, form, &fit);
    Ok(Shaped { symmetrized, fit, setpoints, rings })
}

/// Whether the legs of `mannequin`, ended at `stop`, reach every ring of `form` that shapes
/// them where `fit` placed it.
fn check_legs_reach(
    mannequin: &Mannequin,
    form: &FormDescription,
    fit: &FormFit,
    stop: StopAt,
) -> Result<(), ShapeError> {
    let end = mannequin.left_leg.first().map_or(f64::INFINITY, |layer| layer.z);
    let on_legs =
        |ring: &str| form.rings.iter().any(|r| r.name == ring && region_of(r) != Region::Torso);
    match fit.rings.iter().find(|r| on_legs(&r.ring) && r.mannequin_height_mm < end) {
        Some(r) => Err(ShapeError::BelowTheLegs {
            ring: r.ring.clone(),
            z: r.mannequin_height_mm,
            end,
            stop: stop.name(),
        }),
        None => Ok(()),
    }
}

/// The scan's (`body`'s) and the mannequin's girths at every ring of `form` as `fit` placed
/// them.
fn ring_girths(body: &SegmentedBody, form: &FormDescription, fit: &FormFit) -> Vec<RingGirths> {
    let heights: Vec<f64> = fit.rings.iter().map(|r| r.mannequin_height_mm).collect();
    let scanned = girths_at_rings(body, form, &heights);
    fit.rings
        .iter()
        .zip(scanned)
        .map(|(r, scan_mm)| RingGirths {
            ring: r.ring.clone(),
            body_z_mm: r.mannequin_height_mm,
            scan_mm,
            mannequin_mm: r.mannequin_girth_mm,
        })
        .collect()
}

/// The tape girth of `body` for each ring of `form`, in the form's order, at the body height
/// `heights` gives for it: the section of the ring's region there (`None` where the body has
/// none). The body is cut once per region, at the heights of all the rings shaping it.
pub fn girths_at_rings(
    body: &SegmentedBody,
    form: &FormDescription,
    heights: &[f64],
) -> Vec<Option<f64>> {
    let mut scanned: BTreeMap<&str, Option<f64>> = BTreeMap::new();
    for region in regions_of(form) {
        let rings: Vec<(&str, f64)> = form
            .rings
            .iter()
            .zip(heights)
            .filter(|(ring, _)| region_of(ring) == region)
            .map(|(ring, &z)| (ring.name.as_str(), z))
            .collect();
        let at: Vec<f64> = rings.iter().map(|r| r.1).collect();
        for (&(name, _), section) in rings.iter().zip(body.sections_of(region, &at)) {
            scanned.insert(name, section.map(|c| c.tape_girth()));
        }
    }
    form.rings.iter().map(|ring| scanned.get(ring.name.as_str()).copied().flatten()).collect()
}
