//! `dressform fit-test <garment> (--sim | --serial <path> | --slcan <path> | --can <iface>)
//! (--mannequin <dir> | --scan <scan>) [--form <form.toml>] [--out <dir>]
//! [--sweep [FROM:TO:STEP]] [--json]`: a garment on the form shaped to the customer, judged by
//! the pressure its panels feel (see [`dressform::form::fit_test`]).
//!
//! The form is shaped as `run` shapes it (from the mannequin's `profiles.json`, or from a
//! scan through the whole pipeline), the forces are read at rest, and each ring the garment
//! covers is reported: its girth on the form, the ease, the mean and largest pressure, the
//! imbalance and the verdict. With `--sweep` every covered ring's girth steps through the range
//! and the report says where the garment binds and its usable range. Writes `fit-test.json`,
//! `fit.png` (and `sweep.svg`) into `--out` as one set (with `--scan`, what `run` writes
//! into `--out/customer`, a set of its own). With `--sim` the simulated form wears the
//! garment. A panel over its force limit stops the test (exit 1).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use dressform::atomic_output::OutputSet;
use dressform::body::mesh::decimate::WORKING_TRIANGLES;
use dressform::body::scan::{self, ScanOptions};
use dressform::form::controller::{DEFAULT_FORCE_WINDOW, DriveOptions, DriveReport};
use dressform::form::fit_test::sweep::{self, DEFAULT_SWEEP, SweepRange, SweepStep};
use dressform::form::fit_test::{self, FitTest};
use dressform::form::form_fit::{Targets, compare, fit, regions_of};
use dressform::form::setpoints::SetPoints;
use dressform::run::outputs::{GARMENT_FIT, REPORT, SWEEP, fit_test_report};
use dressform::run::preview::{fit_png, sweep_svg};
use dressform::run::reconstruct::ReconstructOptions;
use dressform::run::report;
use dressform::shape::profiles::Profiles;
use form_description::FormDescription;
use form_description::garment::{GarmentSpec, SHIPPED, shipped};
use serde::Serialize;

use super::drive::{ShapeArgs, SimArgs, execute_through, shape_verdict};
use super::link::{FormArg, LinkArgs};
use super::run::{Drive, Moves, Prepared, Reconstruct, shape_form_through};
use super::{Failure, FrameArgs, ReportArgs, SmoothArgs, print_warnings};

/// The customer the form is shaped to.
#[derive(Debug, clap::Args)]
#[group(required = true, multiple = false)]
pub struct CustomerArgs {
    /// A mannequin folder written by `run`, `reconstruct` or `symmetrize` (its profiles.json).
    #[arg(long, value_name = "DIR")]
    mannequin: Option<PathBuf>,
    /// A body scan (.obj, .ply or .stl), taken through the whole pipeline as `run` does.
    #[arg(long, value_name = "SCAN")]
    scan: Option<PathBuf>,
}

#[derive(Debug, clap::Args)]
pub struct FitTestArgs {
    /// The garment description (TOML), or a shipped garment's name (woven-dress,
    /// woven-dress-small-waist, jersey-top, compression-garment).
    garment: PathBuf,
    #[command(flatten)]
    customer: CustomerArgs,
    #[command(flatten)]
    form: FormArg,
    #[command(flatten)]
    link: LinkArgs,
    #[command(flatten)]
    sim: SimArgs,
    #[command(flatten)]
    shape: ShapeArgs,
    /// Step every ring the garment covers through this range of girths around the
    /// customer's, mm, reading the pressure at each step (`--sweep`, or `--sweep=-20:60:10`;
    /// the range includes 0).
    #[arg(long, value_name = "FROM:TO:STEP", num_args = 0..=1, require_equals = true, default_missing_value = DEFAULT_SWEEP, allow_hyphen_values = true)]
    sweep: Option<String>,
    /// Where to write fit-test.json, fit.png (and with --sweep sweep.svg) and report.html;
    /// with --scan, what `run` writes goes into its folder `customer`.
    #[arg(long, default_value = "dressform-fit-test")]
    out: PathBuf,
    /// Print the report as JSON on standard output (with --mannequin; with --scan the
    /// pipeline reports in text, and fit-test.json has the fit).
    #[arg(long, conflicts_with = "scan")]
    json: bool,
    /// The body model (.glb), with --scan [default: the built-in model].
    #[arg(long)]
    model: Option<PathBuf>,
    #[command(flatten)]
    frame: FrameArgs,
    #[command(flatten)]
    smooth: SmoothArgs,
    #[command(flatten)]
    report: ReportArgs,
}

/// The fit test's JSON (`fit-test.json`).
#[derive(Serialize)]
struct Report<'a> {
    format: &'static str,
    /// The fit at the customer's girths.
    fit: &'a FitTest,
    /// The sweep, with `--sweep`.
    #[serde(skip_serializing_if = "Option::is_none")]
    sweep: Option<&'a sweep::Sweep>,
}

/// Where `--scan` puts what `run` writes, in `--out`.
const CUSTOMER_DIR: &str = "customer";

/// The format name of `fit-test.json`.
const FORMAT: &str = "dressform-fit-test/1";

pub fn run(args: &FitTestArgs) -> Result<(), Failure> {
    // Everything checked before the form is claimed.
    let form = args.form.load()?;
    let garment = load_garment(&args.garment, &form)?;
    let range: Option<SweepRange> = match &args.sweep {
        Some(text) => Some(text.parse().map_err(|e| Failure::bad_input(format!("--sweep {e}")))?),
        None => None,
    };
    let tolerance = args.shape.tolerance()?;
    let options = DriveOptions { read_forces: Some(DEFAULT_FORCE_WINDOW), ..args.shape.options() };
    let link = args.link.spec();
    let deltas = range.map_or_else(|| vec![0.0], |r| r.deltas());
    let (steps_form, steps_garment) = (form.clone(), garment.clone());
    let steps_of = move |base: &SetPoints| -> Vec<SetPoints> {
        deltas
            .iter()
            .map(|&d| sweep::step_setpoints(&steps_form, &steps_garment, base, d))
            .collect()
    };
    let (base, reports, shape) = match (&args.customer.mannequin, &args.customer.scan) {
        (Some(dir), _) => {
            // Read before the form is claimed: a bad folder moves nothing.
            let path = dir.join("profiles.json");
            let profiles = Profiles::load(&path, &regions_of(&form)).map_err(Failure::bad_input)?;
            let fit_form = form.clone();
            let compute = move || {
                let fitted = fit(&profiles, &fit_form)
                    .map_err(|e| Failure::bad_input(format!("{}: {e}", path.display())))?;
                let base = fitted.setpoints();
                let steps = steps_of(&base);
                Ok((base, steps))
            };
            let (base, reports) = execute_through(
                &form,
                &link,
                &options,
                &args.sim,
                Some(garment.clone()),
                args.json,
                compute,
            )?;
            for (id, asked, used) in reports.iter().flat_map(|r| &r.clamped) {
                errln!("warning: {id}: {asked} mm is outside the stroke, clamped to {used} mm");
            }
            for warning in reports.iter().flat_map(|r| &r.warnings) {
                errln!("warning: {warning}");
            }
            let at = customer_step(&reports, range);
            let targets =
                Targets { girths_mm: &base.target_girths_mm, heights_mm: &base.target_heights_mm };
            let shape = compare(&form, &reports[at].positions_mm, targets, tolerance);
            (base, reports, shape)
        }
        (None, Some(scan_path)) => {
            let drive = Drive { link: &link, sim: &args.sim, options: &options, tolerance };
            let scan_options = ScanOptions {
                frame: args.frame.options(),
                smooth: args.smooth.smooth,
                max_triangles: Some(WORKING_TRIANGLES),
            };
            let (scan_path, model_path) = (scan_path.clone(), args.model.clone());
            let prepare = move || {
                let model = super::model::load(model_path.as_deref())?;
                let scan::PreparedScan { scan, warnings, .. } =
                    scan::prepare(&scan_path, &scan_options).map_err(Failure::bad_input)?;
                print_warnings(&scan.source.display().to_string(), &warnings, None);
                let reconstruct = Reconstruct { model, options: ReconstructOptions::default() };
                let report = Default::default();
                Ok(Prepared { scan, reconstruct, outputs: OutputSet::new(), extra: (), report })
            };
            let moves = Moves { steps: Box::new(steps_of), garment: Some(garment.clone()) };
            // The pipeline's outputs are a set of their own, beside the fit test's.
            let customer = args.out.join(CUSTOMER_DIR);
            let (done, shape, (), reports) =
                shape_form_through(&form, &drive, &customer, prepare, moves)?;
            (done.shaped.setpoints, reports, shape)
        }
        (None, None) => return Err(Failure::bad_input("give --mannequin DIR or --scan SCAN")),
    };
    let fits: Vec<FitTest> = reports
        .iter()
        .zip(range.map_or_else(|| vec![0.0], |r| r.deltas()))
        .map(|(report, delta)| assess_step(&form, &garment, &base, report, delta))
        .collect();
    let at = customer_step(&reports, range);
    let swept = range.map(|r| {
        let steps = r
            .deltas()
            .into_iter()
            .zip(&fits)
            .map(|(delta_mm, fit)| SweepStep { delta_mm, fit: fit.clone() })
            .collect();
        sweep::analyse(steps, sweep::limit_for(garment.kind))
    });
    let fit = &fits[at];
    let (customer, copy) = (&args.customer, &args.report);
    write_outputs(&args.out, &form, fit, &reports[at], swept.as_ref(), customer, copy)?;
    if args.json {
        let report = Report { format: FORMAT, fit, sweep: swept.as_ref() };
        outln!("{}", serde_json::to_string_pretty(&report).map_err(Failure::other)?);
    } else {
        out!("{}", fit_test::table(fit));
        if let Some(swept) = &swept {
            outln!("size sweep ({} steps):", swept.steps.len());
            out!("{}", sweep::table(swept));
        }
        let svg = if swept.is_some() { ", sweep.svg" } else { "" };
        outln!("fit-test.json, fit.png{svg} and report.html written to {}", args.out.display());
    }
    shape_verdict(&shape)
}

/// The garment: a file, else a shipped garment of that name, checked against `form`.
fn load_garment(path: &Path, form: &FormDescription) -> Result<GarmentSpec, Failure> {
    let text = if path.exists() {
        std::fs::read_to_string(path)
            .map_err(|e| Failure::bad_input(format!("{}: cannot read: {e}", path.display())))?
    } else {
        let names: Vec<&str> = SHIPPED.iter().map(|(n, _)| *n).collect();
        path.to_str().and_then(shipped).map(str::to_string).ok_or_else(|| {
            Failure::bad_input(format!(
                "{}: no such file, and not a shipped garment ({})",
                path.display(),
                names.join(", ")
            ))
        })?
    };
    GarmentSpec::from_toml_str(&text, form)
        .map_err(|e| Failure::bad_input(format!("{}: {e}", path.display())))
}

/// Which step is the customer's own girths: the sweep's step at 0 mm (else the nearest), or
/// the only one.
fn customer_step(reports: &[DriveReport], range: Option<SweepRange>) -> usize {
    let deltas = range.map_or_else(|| vec![0.0], |r| r.deltas());
    let nearest = (0..deltas.len().min(reports.len()))
        .min_by(|&a, &b| deltas[a].abs().total_cmp(&deltas[b].abs()));
    nearest.unwrap_or(0)
}

/// The fit at one step: the body's girths grown by the step's offset.
fn assess_step(
    form: &FormDescription,
    garment: &GarmentSpec,
    base: &SetPoints,
    report: &DriveReport,
    delta_mm: f64,
) -> FitTest {
    let girths: BTreeMap<String, f64> =
        base.target_girths_mm.iter().map(|(ring, g)| (ring.clone(), g + delta_mm)).collect();
    fit_test::assess(form, garment, &girths, &report.positions_mm, &report.forces)
}

/// `fit-test.json`, `fit.png`, `sweep.svg` and the report of the fit test on `customer` into
/// `out`, as one set; the report also where `copy` says.
fn write_outputs(
    out: &Path,
    form: &FormDescription,
    fit: &FitTest,
    report: &DriveReport,
    swept: Option<&sweep::Sweep>,
    customer: &CustomerArgs,
    copy: &ReportArgs,
) -> Result<(), Failure> {
    let mut outputs = OutputSet::new();
    let json = Report { format: FORMAT, fit, sweep: swept };
    let text = serde_json::to_string_pretty(&json).map_err(Failure::other)?;
    outputs.add("fit-test.json", text + "\n");
    outputs.add(GARMENT_FIT, fit_png(form, fit, &report.positions_mm));
    if let Some(swept) = swept {
        outputs.add(SWEEP, sweep_svg(swept));
    }
    // The customer: the mannequin's folder's name, or the scan's file stem (else as given).
    let (folder, scan) = (customer.mannequin.as_deref(), customer.scan.as_deref());
    let name = folder.and_then(Path::file_name).or(scan.and_then(Path::file_stem));
    let name = name.or(folder.or(scan).map(Path::as_os_str)).unwrap_or_default();
    let name = name.to_string_lossy().into_owned();
    let html = report::render(&fit_test_report(name, fit, swept, &outputs));
    outputs.add(REPORT, html);
    copy.commit(outputs, out)
}
