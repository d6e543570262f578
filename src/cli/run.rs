//! `dressform run <scan> [--form <form.toml>] (--sim | --serial <path> | --slcan <path> |
//! --can <iface>) [--out <dir>] [--girth-tolerance <mm>] [--reset-faults]`: scan to shaped
//! form in one command — the symmetric mannequin, the set-points that give the form its
//! shape, the drive — and a final report comparing the scan's, the mannequin's and the form's
//! girths at every ring. Exit status 3 when a ring did not reach the mannequin's girth.

use super::drive::{ShapeArgs, SimArgs, execute, shape_verdict};
use super::link::{FormArg, LinkArgs};
use super::setpoints::fidelity_table;
use super::{Failure, FrameArgs, SmoothArgs, progress_bar, warn};
use dressform::controller::{DriveOptions, LinkSpec};
use dressform::fitting::{ShapeOutcome, compare};
use dressform::mannequin::MannequinOptions;
use dressform::mesh::topology;
use dressform::output::OutputSet;
use dressform::outputs::Outputs;
use dressform::pipeline::{RingGirths, SHAPE_STEPS, Symmetrized, shape};
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
    /// Where to write mannequin.obj, profiles.json, measurements.json, setpoints.json,
    /// preview.png and sections.svg.
    #[arg(long, default_value = "dressform-run")]
    out: PathBuf,
    #[command(flatten)]
    frame: FrameArgs,
    #[command(flatten)]
    smooth: SmoothArgs,
}

pub fn run(args: &RunArgs) -> Result<(), Failure> {
    let form = args.form.load()?;
    let girth_tolerance = args.shape.girth_tolerance()?;
    let mut scan = scan::load(&args.scan, &args.frame.options()).map_err(Failure::bad_input)?;
    let file = scan.source.display().to_string();
    for w in scan.cleaning.warnings().into_iter().chain(topology(&scan.body).warnings()) {
        warn(&file, &w);
    }
    scan.body.taubin_smooth(args.smooth.smooth);
    let link = args.link.spec();
    let drive =
        Drive { link: &link, sim: &args.sim, options: &args.shape.options(), girth_tolerance };
    let (_, shape) = shape_form(&scan, &form, &drive, &args.out, OutputSet::new())?;
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

/// The chain shared by `run` and `demo`: mannequin, set-points, drive, report. The outputs are
/// committed into `out` with the files already in `outputs`, as one set. Returns the mannequin
/// and its measurements, and how well the form took the shape (the caller exits 3 when it did
/// not).
pub fn shape_form(
    scan: &Scan,
    form: &FormDescription,
    drive: &Drive,
    out: &Path,
    mut outputs: OutputSet,
) -> Result<(Symmetrized, ShapeOutcome), Failure> {
    let file = scan.source.display().to_string();
    let bar = progress_bar(false, SHAPE_STEPS.len() as u64);
    let shaped = shape(scan, &MannequinOptions::default(), form, |step| {
        bar.inc(1);
        bar.set_message(SHAPE_STEPS[step]);
    })
    .map_err(|e| Failure::bad_input(format!("{file}: {e}")))?;
    let export = Export::canonical(Format::Obj);
    let files = Outputs::of(&shaped.symmetrized, scan, &export).with_setpoints(&shaped.setpoints);
    outputs.append(files.files().map_err(Failure::other)?);
    outputs.commit(out).map_err(Failure::other)?;
    bar.finish_and_clear();

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
    out!("{}", girth_table(&shaped.rings, &shape));
    Ok((shaped.symmetrized, shape))
}

/// Scan, mannequin and form girths at every ring: the scan's section where the ring shapes
/// the body, the mannequin's there, and the form's skin at the positions reached, with the
/// ring's status.
fn girth_table(rings: &[RingGirths], shape: &ShapeOutcome) -> String {
    use std::fmt::Write;
    let mut s = String::new();
    let _ = writeln!(
        s,
        "  {:<12} {:>9} {:>9} {:>11} {:>9}  status",
        "girth (mm)", "body z", "scan", "mannequin", "form"
    );
    for r in rings {
        let scanned = r.scan_mm.map_or_else(|| "-".to_string(), |g| format!("{g:.1}"));
        let (reached, status) = match shape.rings.iter().find(|o| o.ring == r.ring) {
            Some(o) => (format!("{:.1}", o.reached_mm), shape.status(o)),
            None => ("-".into(), "no body".into()),
        };
        let _ = writeln!(
            s,
            "  {:<12} {:>9.0} {:>9} {:>11.1} {:>9}  {status}",
            r.ring, r.body_z_mm, scanned, r.mannequin_mm, reached
        );
    }
    s
}
