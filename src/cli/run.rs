//! `dressform run <scan> [--form <form.toml>] (--sim | --serial <path> | --slcan <path> |
//! --can <iface>) [--out <dir>] [--model <model.glb>] [--pose <pose.toml>]
//! [--girth-tolerance <mm>] [--reset-faults] [--report PATH]`: scan to shaped form in one
//! command — pose symmetry (the body model fitted, the scan re-posed symmetric), the symmetric
//! mannequin, the set-points that give the form its shape, the drive — and a final report
//! comparing the scan's, the pose-symmetric scan's, the mannequin's and the form's girths at
//! every ring.
//! Exit status 3 when a ring did not reach the mannequin's girth.

use super::drive::{ShapeArgs, SimArgs, execute_through, shape_verdict};
use super::link::{FormArg, LinkArgs};
use super::setpoints::fidelity_table;
use super::{Failure, FrameArgs, LegArgs, ReportArgs, SmoothArgs, print_warnings, progress_bar};
use dressform::atomic_output::OutputSet;
use dressform::body::mesh::decimate::WORKING_TRIANGLES;
use dressform::body::scan::{self, Scan, ScanOptions, format::Export, format::Format};
use dressform::form::controller::{DriveOptions, DriveReport, LinkSpec};
use dressform::form::form_fit::{ShapeOutcome, Targets, Tolerance, compare};
use dressform::form::setpoints::SetPoints;
use dressform::pose::body_model::BodyModel;
use dressform::pose::model_fit::verdict::RegionResidual;
use dressform::run::outputs::Outputs;
use dressform::run::pipeline::SHAPE_STEPS;
use dressform::run::reconstruct::{ReconstructOptions, Reshaped, STEPS, reconstruct_shape};
use form_description::FormDescription;
use form_description::garment::GarmentSpec;
use std::path::{Path, PathBuf};

#[derive(Debug, clap::Args)]
pub struct RunArgs {
    /// The scan: an .obj, .ply or .stl file.
    scan: PathBuf,
    #[command(flatten)]
    form: FormArg,
    #[command(flatten)]
    link: LinkArgs,
    #[command(flatten)]
    sim: SimArgs,
    #[command(flatten)]
    shape: ShapeArgs,
    /// Where to write mannequin.obj, posed.obj, rigged.glb, fit.json, profiles.json,
    /// measurements.json, setpoints.json, preview.png, sections.svg, form-fit.png and
    /// report.html.
    #[arg(long, default_value = "dressform-run")]
    out: PathBuf,
    /// The body model (.glb) [default: the built-in model].
    #[arg(long)]
    model: Option<PathBuf>,
    /// Joint angles to set on the symmetric pose (TOML; see docs/formats.md).
    #[arg(long)]
    pose: Option<PathBuf>,
    #[command(flatten)]
    frame: FrameArgs,
    #[command(flatten)]
    smooth: SmoothArgs,
    #[command(flatten)]
    legs: LegArgs,
    #[command(flatten)]
    report: ReportArgs,
}

pub fn run(args: &RunArgs) -> Result<(), Failure> {
    let form = args.form.load()?;
    let tolerance = args.shape.tolerance()?;
    let link = args.link.spec();
    let drive = Drive { link: &link, sim: &args.sim, options: &args.shape.options(), tolerance };
    // Read and checked once the form is claimed (see `shape_form`): nothing here moves it.
    let scan_path = args.scan.clone();
    let scan_options = ScanOptions {
        frame: args.frame.options(),
        smooth: args.smooth.smooth,
        max_triangles: Some(WORKING_TRIANGLES),
    };
    let (model_path, pose_path) = (args.model.clone(), args.pose.clone());
    let legs = args.legs.options();
    let report = ReportTo { customer: None, also: args.report.clone() };
    let prepare = move || {
        let model = super::model::load(model_path.as_deref())?;
        let pose = super::reconstruct::pose_overrides(pose_path.as_deref(), &model)?;
        let scan::PreparedScan { scan, warnings, .. } =
            scan::prepare(&scan_path, &scan_options).map_err(Failure::bad_input)?;
        print_warnings(&scan.source.display().to_string(), &warnings, None);
        let options = ReconstructOptions { pose, mannequin: legs, ..Default::default() };
        let reconstruct = Reconstruct { model, options };
        Ok(Prepared { scan, reconstruct, outputs: OutputSet::new(), extra: (), report })
    };
    let (_, shape, ()) = shape_form(&form, &drive, &args.out, prepare)?;
    shape_verdict(&shape)
}

/// How `run` and `demo` drive the form.
pub struct Drive<'a> {
    /// Where the form is.
    pub link: &'a LinkSpec,
    /// The simulated form's log and faults.
    pub sim: &'a SimArgs,
    /// The drive's options.
    pub options: &'a DriveOptions,
    /// How far a ring may be off the mannequin's girth and its body level.
    pub tolerance: Tolerance,
}

/// How `run` and `demo` make the pose-symmetric scan.
pub struct Reconstruct {
    /// The body model.
    pub model: BodyModel,
    /// The fit, the symmetric pose's overrides, the mannequin's options.
    pub options: ReconstructOptions,
}

/// Whom the customer report (`report.html`) of `run` and `demo` names, and where else it goes.
#[derive(Debug, Clone, Default)]
pub struct ReportTo {
    /// The customer (default: the scan's file stem).
    pub customer: Option<String>,
    /// `--report`.
    pub also: ReportArgs,
}

/// What `run` and `demo` prepare before the reconstruction: the scan, how to reconstruct it,
/// the output files made on the way, the report's customer and copy, and anything else the
/// caller wants back (`extra`).
pub struct Prepared<X> {
    /// The scan, in the canonical frame and prepared ([`scan::prepare`]).
    pub scan: Scan,
    /// The body model and options.
    pub reconstruct: Reconstruct,
    /// Files to commit with the reconstruction's, as one set.
    pub outputs: OutputSet,
    /// The caller's own.
    pub extra: X,
    /// Whom the report names and where else it goes.
    pub report: ReportTo,
}

/// The chain shared by `run` and `demo`: the form claimed first (its endpoint and signals
/// armed, the e-stops latched on it recorded; see `execute`), then — while the link is kept
/// alive — `prepare` (reading or making the scan), pose symmetry, mannequin and set-points
/// on a thread of their own, the outputs committed into `out` as one set; then the drive and
/// the report. An e-stop at any point ends the command (exit 1). Returns the reconstruction,
/// how well the form took the shape (the caller exits 3 when it did not) and `prepare`'s
/// extra. A fit that does not match the scan is an error (exit 2), never a mannequin.
pub fn shape_form<X: Send + 'static>(
    form: &FormDescription,
    drive: &Drive,
    out: &Path,
    prepare: impl FnOnce() -> Result<Prepared<X>, Failure> + Send + 'static,
) -> Result<(Reshaped, ShapeOutcome, X), Failure> {
    let (done, shape, extra, _) = shape_form_through(form, drive, out, prepare, Moves::shape())?;
    Ok((done, shape, extra))
}

/// Makes a command's steps from the mannequin's set-points: one move each.
pub type StepsOf = Box<dyn FnOnce(&SetPoints) -> Vec<SetPoints> + Send>;

/// What the form is driven through once the mannequin's set-points are known.
pub struct Moves {
    /// The steps, made from the mannequin's set-points.
    pub steps: StepsOf,
    /// What the simulated form wears (with `--sim`).
    pub garment: Option<GarmentSpec>,
}

impl Moves {
    /// The mannequin's shape, once (`run`, `demo`).
    pub fn shape() -> Self {
        Self { steps: Box::new(|setpoints| vec![setpoints.clone()]), garment: None }
    }
}

/// [`shape_form`] through `moves` (the mannequin's set-points first made into steps: a fit
/// test's sweep), with every step's report; the shape is judged at the step that is the
/// mannequin's set-points (else the first).
pub fn shape_form_through<X: Send + 'static>(
    form: &FormDescription,
    drive: &Drive,
    out: &Path,
    prepare: impl FnOnce() -> Result<Prepared<X>, Failure> + Send + 'static,
    moves: Moves,
) -> Result<(Reshaped, ShapeOutcome, X, Vec<DriveReport>), Failure> {
    let (shape_of, out_dir) = (form.clone(), out.to_path_buf());
    let device = match drive.link {
        LinkSpec::Sim => "simulated bus".to_string(),
        LinkSpec::Serial(path) | LinkSpec::Slcan(path) => path.display().to_string(),
        LinkSpec::Can(interface) => interface.clone(),
    };
    // Said once the form is claimed, as the computation starts: from here on an e-stop ends
    // the command.
    let claimed = format!(
        "{device}: form \"{}\" claimed ({} nodes answer); an e-stop from now on ends this command",
        form.name,
        form.nodes.len()
    );
    let compute = move || {
        errln!("{claimed}");
        let Prepared { scan, reconstruct, outputs, extra, report } = prepare()?;
        let done =
            reconstruct_and_write(&scan, &reconstruct, &shape_of, &out_dir, outputs, &report)?;
        let steps = (moves.steps)(&done.shaped.setpoints);
        let at = steps.iter().position(|s| *s == done.shaped.setpoints).unwrap_or(0);
        Ok(((done, extra, at), steps))
    };
    let ((done, extra, at), reports) =
        execute_through(form, drive.link, drive.options, drive.sim, moves.garment, false, compute)?;
    for warning in reports.iter().flat_map(|r| &r.warnings) {
        errln!("warning: {warning}");
    }
    let report = &reports[at];
    let setpoints = &done.shaped.setpoints;
    let targets = Targets {
        girths_mm: &setpoints.target_girths_mm,
        heights_mm: &setpoints.target_heights_mm,
    };
    let shape = compare(form, &report.positions_mm, targets, drive.tolerance);
    outln!(
        "{} on {}: {} actuators moved together in {} ms; {}.",
        report.form,
        report.device,
        report.actuators.len(),
        report.duration_ms,
        if shape.summary().is_some() {
            "every actuator reached its set-point, but the form could NOT take the shape"
        } else {
            "every actuator reached its set-point and every ring the mannequin's girth and level"
        }
    );
    outln!();
    out!("{}", girth_table(&done, &shape));
    Ok((done, shape, extra, reports))
}

/// Pose symmetry, mannequin and set-points of `scan`, committed into `out` with the files
/// already in `outputs` as one set (the report as `report` says), and the fit and the form's
/// fit printed.
fn reconstruct_and_write(
    scan: &Scan,
    reconstruct: &Reconstruct,
    form: &FormDescription,
    out: &Path,
    mut outputs: OutputSet,
    report: &ReportTo,
) -> Result<Reshaped, Failure> {
    let bar = progress_bar(false, (STEPS.len() + SHAPE_STEPS.len()) as u64);
    let done = reconstruct_shape(scan, &reconstruct.model, &reconstruct.options, form, |step| {
        bar.inc(1);
        bar.set_message(STEPS.iter().chain(&SHAPE_STEPS).nth(step).copied().unwrap_or(""));
    })
    .map_err(|e| Failure::bad_input(scan.failed(e)))?;
    let (shaped, export) = (&done.shaped, Export::canonical(Format::Obj));
    let mut files =
        Outputs::reposed(&shaped.symmetrized, &done.reposed, &done.as_scanned, scan, &export)
            .with_form(form, &shaped.fit, &shaped.setpoints);
    if let Some(customer) = &report.customer {
        files = files.with_customer(customer);
    }
    outputs.append(files.files().map_err(Failure::other)?);
    report.also.commit(outputs, out)?;
    bar.finish_and_clear();

    let over = |r: &&RegionResidual| r.median_mm / r.max_median_mm;
    let worst = done.reposed.residuals.iter().max_by(|a, b| over(a).total_cmp(&over(b)));
    if let Some(worst) = worst {
        outln!(
            "Body model fitted in {:.1} s ({} iterations; closest to its limit the {}, {:.1} mm from the scan, at most {:.0}), the scan re-posed symmetric.",
            done.reposed.fit_seconds,
            done.reposed.fit.iterations,
            worst.region,
            worst.median_mm,
            worst.max_median_mm
        );
    }
    outln!("Symmetric mannequin and set-points written to {}.", out.display());
    outln!("Fit of form \"{}\" (ring heights on the form and on the body):", form.name);
    out!("{}", fidelity_table(&shaped.fit));
    outln!();
    Ok(done)
}

/// Scan, pose-symmetric scan, mannequin and form girths at every ring: the scan's section
/// where the ring shapes the body (as it stood, and re-posed), the mannequin's there, and the
/// form's skin at the positions reached, with the ring's status.
fn girth_table(done: &Reshaped, shape: &ShapeOutcome) -> String {
    use std::fmt::Write;
    let mm = |g: Option<f64>| g.map_or_else(|| "-".to_string(), |g| format!("{g:.1}"));
    let mut s = String::new();
    let _ = writeln!(
        s,
        "  {:<12} {:>9} {:>9} {:>11} {:>11} {:>9}  status",
        "girth (mm)", "body z", "scan", "pose-symm.", "mannequin", "form"
    );
    for (r, &scanned) in done.shaped.rings.iter().zip(&done.scan_rings) {
        let (reached, status) = match shape.rings.iter().find(|o| o.ring == r.ring) {
            Some(o) => (format!("{:.1}", o.reached_mm), shape.status(o)),
            None => ("-".into(), "no body".into()),
        };
        let _ = writeln!(
            s,
            "  {:<12} {:>9.0} {:>9} {:>11} {:>11.1} {:>9}  {status}",
            r.ring,
            r.body_z_mm,
            mm(scanned),
            mm(r.scan_mm),
            r.mannequin_mm,
            reached
        );
    }
    s
}
