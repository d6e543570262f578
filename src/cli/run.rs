//! `dressform run <scan> [--form <form.toml>] (--sim | --serial <path> | --slcan <path> |
//! --can <iface>) [--out <dir>]`: scan to shaped form in one command — the symmetric
//! mannequin, the set-points that give the form its shape, the drive — and a final report
//! comparing the scan's, the mannequin's and the form's girths at every ring.

use super::drive::{LinkArgs, SimArgs, execute, load_form};
use super::setpoints::fidelity_table;
use super::{Failure, FrameArgs, SmoothArgs, progress_bar, warn};
use dressform::controller::{DriveOptions, DriveReport, LinkSpec};
use dressform::fitting::{Fit, fit, region_of, ring_girth};
use dressform::mannequin::MannequinOptions;
use dressform::mesh::topology;
use dressform::output::write_atomically;
use dressform::pipeline::{STEPS, Symmetrized, symmetrize};
use dressform::preview::{preview_png, sections_svg};
use dressform::profiles::Profiles;
use dressform::regions::Region;
use dressform::scan::{self, Scan, format::Format};
use dressform::setpoints::SetPoints;
use sim::form::FormDescription;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

#[derive(Debug, clap::Args)]
pub struct RunArgs {
    /// The scan: an .obj, .ply or .stl file.
    scan: PathBuf,
    /// The form description (TOML) [default: the built-in reference form].
    #[arg(long)]
    form: Option<PathBuf>,
    #[command(flatten)]
    link: LinkArgs,
    #[command(flatten)]
    sim: SimArgs,
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
    let form = load_form(args.form.as_ref())?;
    let mut scan = scan::load(&args.scan, &args.frame.options()).map_err(Failure::bad_input)?;
    let file = scan.source.display().to_string();
    for w in scan.cleaning.warnings().into_iter().chain(topology(&scan.body).warnings()) {
        warn(&file, &w);
    }
    scan.body.taubin_smooth(args.smooth.smooth);
    shape_form(&scan, &form, &args.link.spec(), &args.sim, &args.out).map(|_| ())
}

/// The chain shared by `run` and `demo`: mannequin, set-points, drive, report. Returns the
/// mannequin and its measurements.
pub fn shape_form(
    scan: &Scan,
    form: &FormDescription,
    link: &LinkSpec,
    sim: &SimArgs,
    out: &Path,
) -> Result<Symmetrized, Failure> {
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
    let setpoints = SetPoints::new(form.name.clone(), fitted.positions_mm.clone());
    write_outputs(out, scan, &result, &profiles, &setpoints)?;
    bar.finish_and_clear();

    outln!("Symmetric mannequin and set-points written to {}.", out.display());
    outln!("Fit of form \"{}\" (ring heights on the form and on the body):", form.name);
    out!("{}", fidelity_table(&fitted));
    outln!();
    let report = execute(form, &setpoints, link, &DriveOptions::default(), sim, false)?;
    outln!(
        "{} on {}: {} actuators moved together in {} ms; {}.",
        report.form,
        report.device,
        report.actuators.len(),
        report.duration_ms,
        if report.converged() {
            "every actuator reached its set-point"
        } else {
            "some actuators did NOT arrive"
        }
    );
    outln!();
    out!("{}", girth_table(scan, &result, form, &fitted, &report));
    Ok(result)
}

fn write_outputs(
    out: &Path,
    scan: &Scan,
    result: &Symmetrized,
    profiles: &Profiles,
    setpoints: &SetPoints,
) -> Result<(), Failure> {
    std::fs::create_dir_all(out).map_err(|e| {
        Failure::other(format!("{}: cannot create the directory: {e}", out.display()))
    })?;
    let outputs = [
        ("mannequin.obj", Format::Obj.encode(&result.mannequin.mesh)),
        ("profiles.json", serde_json::to_vec_pretty(profiles).map_err(Failure::other)?),
        (
            "measurements.json",
            serde_json::to_vec_pretty(&result.comparison).map_err(Failure::other)?,
        ),
        ("preview.png", preview_png(&scan.body, result)),
        ("sections.svg", sections_svg(&scan.body, result).into_bytes()),
    ];
    for (name, bytes) in &outputs {
        write_atomically(&out.join(name), bytes).map_err(Failure::other)?;
    }
    setpoints.save(&out.join("setpoints.json")).map_err(Failure::other)
}

/// Scan, mannequin and form girths at every ring: the scan's section where the ring shapes
/// the body, the mannequin's there, and the form's skin at the positions reached.
fn girth_table(
    scan: &Scan,
    result: &Symmetrized,
    form: &FormDescription,
    fitted: &Fit,
    report: &DriveReport,
) -> String {
    use std::fmt::Write;
    let reached: BTreeMap<String, f64> =
        report.actuators.iter().filter_map(|a| a.reached_mm.map(|r| (a.id.clone(), r))).collect();
    let mut s = String::new();
    let _ = writeln!(
        s,
        "  {:<12} {:>9} {:>9} {:>11} {:>9}",
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
        let _ = writeln!(
            s,
            "  {:<12} {:>9.0} {:>9} {:>11.1} {:>9.1}",
            ring.name,
            z,
            scanned,
            r.mannequin_girth_mm,
            ring_girth(form, ring, &reached)
        );
    }
    s
}
