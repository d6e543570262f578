//! `dressform run <scan> [--form <form.toml>] (--sim | --serial <path> | --slcan <path> |
//! --can <iface>) [--out <dir>] [--girth-tolerance <mm>] [--reset-faults]`: scan to shaped
//! form in one command — the symmetric mannequin, the set-points that give the form its
//! shape, the drive — and a final report comparing the scan's, the mannequin's and the form's
//! girths at every ring. Exit status 3 when a ring did not reach the mannequin's girth.

use super::drive::{ShapeArgs, SimArgs, execute, shape_verdict};
use super::link::{FormArg, LinkArgs};
use super::setpoints::{fidelity_table, setpoints_of};
use super::{Failure, FrameArgs, SmoothArgs, progress_bar, warn};
use dressform::controller::{DriveOptions, LinkSpec};
use dressform::fitting::{Fit, ShapeOutcome, compare, fit, region_of};
use dressform::mannequin::MannequinOptions;
use dressform::mesh::topology;
use dressform::output::OutputSet;
use dressform::pipeline::{STEPS, Symmetrized, symmetrize};
use dressform::preview::{preview_png, sections_svg};
use dressform::profiles::Profiles;
use dressform::regions::Region;
use dressform::scan::{self, Scan, format::Export, format::Format};
use dressform::setpoints::SetPoints;
use form_description::FormDescription;
use std::collections::BTreeMap;
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
    outputs: OutputSet,
) -> Result<(Symmetrized, ShapeOutcome), Failure> {
    let file = scan.source.display().to_string();
    let bar = progress_bar(false, STEPS.len() as u64 + 1);
    let result = symmetrize(scan, &MannequinOptions::default(), |step| {
        bar.inc(1);
        bar.set_message(STEPS[step]);
    })
    .map_err(|e| Failure::bad_input(format!("{file}: {e}")))?;
    bar.set_message("fitting the form");
    let profiles = Profiles::of(&result.mannequin, &result.comparison.levels);
    let fitted = fit(&profiles, form).map_err(|e| Failure::bad_input(format!("{file}: {e}")))?;
    let setpoints = setpoints_of(&fitted);
    write_outputs(out, scan, outputs, &result, &profiles, &setpoints)?;
    bar.finish_and_clear();

    outln!("Symmetric mannequin and set-points written to {}.", out.display());
    outln!("Fit of form \"{}\" (ring heights on the form and on the body):", form.name);
    out!("{}", fidelity_table(&fitted));
    outln!();
    let report = execute(form, &setpoints, drive.link, drive.options, drive.sim, false)?;
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
    out!("{}", girth_table(scan, &result, form, &fitted, &shape));
    Ok((result, shape))
}

fn write_outputs(
    out: &Path,
    scan: &Scan,
    mut outputs: OutputSet,
    result: &Symmetrized,
    profiles: &Profiles,
    setpoints: &SetPoints,
) -> Result<(), Failure> {
    std::fs::create_dir_all(out).map_err(|e| {
        Failure::other(format!("{}: cannot create the directory: {e}", out.display()))
    })?;
    let export = Export::canonical(Format::Obj);
    outputs.add(export.file_name("mannequin"), result.mannequin_file(&export, &scan.frame));
    outputs.add("profiles.json", serde_json::to_vec_pretty(profiles).map_err(Failure::other)?);
    let measurements = serde_json::to_vec_pretty(&result.comparison).map_err(Failure::other)?;
    outputs.add("measurements.json", measurements);
    outputs.add("setpoints.json", setpoints.to_json_string());
    outputs.add("preview.png", preview_png(&[(&scan.body, "scan")], result));
    outputs.add("sections.svg", sections_svg(&scan.body, result));
    outputs.commit(out).map_err(Failure::other)
}

/// Scan, mannequin and form girths at every ring: the scan's section where the ring shapes
/// the body, the mannequin's there, and the form's skin at the positions reached, with the
/// ring's status.
fn girth_table(
    scan: &Scan,
    result: &Symmetrized,
    form: &FormDescription,
    fitted: &Fit,
    shape: &ShapeOutcome,
) -> String {
    use std::fmt::Write;
    let mut s = String::new();
    let _ = writeln!(
        s,
        "  {:<12} {:>9} {:>9} {:>11} {:>9}  status",
        "girth (mm)", "body z", "scan", "mannequin", "form"
    );
    // The scan's sections: one sweep per region for all its rings.
    let mut scanned: BTreeMap<String, String> = BTreeMap::new();
    for region in [Region::Torso, Region::LeftLeg, Region::RightLeg] {
        let rings: Vec<(&str, f64)> = form
            .rings
            .iter()
            .zip(&fitted.rings)
            .filter(|(ring, _)| region_of(ring) == region)
            .map(|(ring, r)| (ring.name.as_str(), r.mannequin_height_mm))
            .collect();
        let heights: Vec<f64> = rings.iter().map(|r| r.1).collect();
        for ((name, _), c) in
            rings.iter().zip(result.regions.sections_of(&scan.body, region, &heights))
        {
            let girth = c.map_or_else(|| "-".to_string(), |c| format!("{:.1}", c.tape_girth()));
            scanned.insert(name.to_string(), girth);
        }
    }
    for (ring, r) in form.rings.iter().zip(&fitted.rings) {
        let z = r.mannequin_height_mm;
        let scanned = &scanned[&ring.name];
        let (reached, status) = match shape.rings.iter().find(|o| o.ring == ring.name) {
            Some(o) => (format!("{:.1}", o.reached_mm), shape.status(o)),
            None => ("-".into(), "no body".into()),
        };
        let _ = writeln!(
            s,
            "  {:<12} {:>9.0} {:>9} {:>11.1} {:>9}  {status}",
            ring.name, z, scanned, r.mannequin_girth_mm, reached
        );
    }
    s
}
