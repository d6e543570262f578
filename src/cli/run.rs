//! `dressform run <scan> [--form <form.toml>] (--sim | --serial <path> | --slcan <path> |
//! --can <iface>) [--out <dir>] [--model <model.glb>] [--pose <pose.toml>]
//! [--girth-tolerance <mm>] [--reset-faults]`: scan to shaped form in one command — pose
//! symmetry (the body model fitted, the scan re-posed symmetric), the symmetric mannequin, the
//! set-points that give the form its shape, the drive — and a final report comparing the
//! scan's, the pose-symmetric scan's, the mannequin's and the form's girths at every ring.
//! Exit status 3 when a ring did not reach the mannequin's girth.

use super::drive::{ShapeArgs, SimArgs, execute, shape_verdict};
use super::link::{FormArg, LinkArgs};
use super::setpoints::fidelity_table;
use super::{Failure, FrameArgs, SmoothArgs, progress_bar, warn};
use dressform::body_model::BodyModel;
use dressform::controller::{DriveOptions, LinkSpec};
use dressform::fit::verdict::RegionResidual;
use dressform::fitting::{ShapeOutcome, compare};
use dressform::mesh::topology;
use dressform::output::OutputSet;
use dressform::outputs::Outputs;
use dressform::pipeline::SHAPE_STEPS;
use dressform::reconstruct::{ReconstructOptions, Reshaped, STEPS, reconstruct_shape};
use dressform::scan::{self, Scan, format::Export, format::Format};
use form_description::FormDescription;
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
    /// measurements.json, setpoints.json, preview.png and sections.svg.
    #[arg(long, default_value = "dressform-run")]
    out: PathBuf,
    /// The body model (.glb) [default: the built-in model].
    #[arg(long)]
    model: Option<PathBuf>,
    /// Joint angles to set on the symmetric pose (TOML; see the README's "Pose symmetry").
    #[arg(long)]
    pose: Option<PathBuf>,
    #[command(flatten)]
    frame: FrameArgs,
    #[command(flatten)]
    smooth: SmoothArgs,
}

pub fn run(args: &RunArgs) -> Result<(), Failure> {
    let form = args.form.load()?;
    let girth_tolerance = args.shape.girth_tolerance()?;
    let model = super::model::load(args.model.as_deref())?;
    let pose = super::reconstruct::pose_overrides(args.pose.as_deref(), &model)?;
    let mut scan = scan::load(&args.scan, &args.frame.options()).map_err(Failure::bad_input)?;
    let file = scan.source.display().to_string();
    for w in scan.cleaning.warnings().into_iter().chain(topology(&scan.body).warnings()) {
        warn(&file, &w);
    }
    scan.body.taubin_smooth(args.smooth.smooth);
    let link = args.link.spec();
    let drive =
        Drive { link: &link, sim: &args.sim, options: &args.shape.options(), girth_tolerance };
    let options = ReconstructOptions { pose, ..Default::default() };
    let reconstruct = Reconstruct { model: &model, options: &options };
    let (_, shape) = shape_form(&scan, &reconstruct, &form, &drive, &args.out, OutputSet::new())?;
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
    /// A ring off the mannequin's girth by more than this is not reached, mm.
    pub girth_tolerance: f64,
}

/// How `run` and `demo` make the pose-symmetric scan.
pub struct Reconstruct<'a> {
    /// The body model.
    pub model: &'a BodyModel,
    /// The fit, the symmetric pose's overrides, the mannequin's options.
    pub options: &'a ReconstructOptions,
}

/// The chain shared by `run` and `demo`: pose symmetry, mannequin, set-points, drive, report.
/// The outputs are committed into `out` with the files already in `outputs`, as one set.
/// Returns the reconstruction, and how well the form took the shape (the caller exits 3 when
/// it did not). A fit that does not match the scan is an error (exit 2), never a mannequin.
pub fn shape_form(
    scan: &Scan,
    reconstruct: &Reconstruct,
    form: &FormDescription,
    drive: &Drive,
    out: &Path,
    mut outputs: OutputSet,
) -> Result<(Reshaped, ShapeOutcome), Failure> {
    let file = scan.source.display().to_string();
    let bar = progress_bar(false, (STEPS.len() + SHAPE_STEPS.len()) as u64);
    let done = reconstruct_shape(scan, reconstruct.model, reconstruct.options, form, |step| {
        bar.inc(1);
        bar.set_message(STEPS.iter().chain(&SHAPE_STEPS).nth(step).copied().unwrap_or(""));
    })
    .map_err(|e| Failure::bad_input(format!("{file}: {e}")))?;
    let (shaped, export) = (&done.shaped, Export::canonical(Format::Obj));
    let files = Outputs::reposed(&shaped.symmetrized, &done.reposed, scan, &export)
        .with_setpoints(&shaped.setpoints);
    outputs.append(files.files().map_err(Failure::other)?);
    outputs.commit(out).map_err(Failure::other)?;
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
    let setpoints = &shaped.setpoints;
    let report = execute(form, setpoints, drive.link, drive.options, drive.sim, false)?;
    for warning in &report.warnings {
        errln!("warning: {warning}");
    }
    let shape =
        compare(form, &report.positions_mm, &setpoints.target_girths_mm, drive.girth_tolerance);
    outln!(
        "{} on {}: {} actuators moved together in {} ms; {}.",
        report.form,
        report.device,
        report.actuators.len(),
        report.duration_ms,
        if shape.summary().is_some() {
            "every actuator reached its set-point, but the form could NOT take the shape"
        } else {
            "every actuator reached its set-point and every ring the mannequin's girth"
        }
    );
    outln!();
    out!("{}", girth_table(&done, &shape));
    Ok((done, shape))
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
