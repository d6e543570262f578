//! `dressform reconstruct <scan> -o <dir> [--model model.glb] [--pose pose.toml]
//! [--format ...] [--units ...] [--up ...] [--scan-frame] [--json]`: pose symmetry, then the
//! mannequin (see [`dressform::reconstruct`]).

use super::symmetrize::pretty_json;
use super::{ExportArgs, Failure, MannequinArgs, ScanFrameArgs, SmoothArgs, progress_bar, warn};
use dressform::mesh::topology;
use dressform::output::OutputSet;
use dressform::pipeline;
use dressform::pose_symmetry::PoseOverrides;
use dressform::preview::preview_png;
use dressform::profiles::Profiles;
use dressform::reconstruct::{ReconstructOptions, Reconstruction, STEPS, reconstruct};
use dressform::scan;
use std::path::PathBuf;

#[derive(Debug, clap::Args)]
pub struct ReconstructArgs {
    /// The scan: an .obj, .ply or .stl file.
    scan: PathBuf,
    /// Output directory (created if missing): posed.obj, mannequin.obj (or .ply, .stl, .glb),
    /// rigged.glb, profiles.json, measurements.json, fit.json, preview.png, replaced as a whole.
    #[arg(short, long)]
    out: PathBuf,
    /// The body model (.glb) [default: the built-in model].
    #[arg(long)]
    model: Option<PathBuf>,
    /// Joint angles to set on the symmetric pose (TOML; see the README's "Pose symmetry").
    #[arg(long)]
    pose: Option<PathBuf>,
    #[command(flatten)]
    mannequin: MannequinArgs,
    #[command(flatten)]
    export: ExportArgs,
    /// Print fit.json to standard output instead of the table.
    #[arg(long)]
    json: bool,
    #[command(flatten)]
    frame: ScanFrameArgs,
    #[command(flatten)]
    smooth: SmoothArgs,
}

pub fn run(args: &ReconstructArgs) -> Result<(), Failure> {
    let steps = STEPS.len() + pipeline::STEPS.len();
    let bar = progress_bar(args.json, steps as u64 + 2);
    bar.set_message("reading the scan");
    let model = super::model::load(args.model.as_deref())?;
    let pose = match &args.pose {
        Some(path) => PoseOverrides::load(path, &model.skeleton).map_err(Failure::bad_input)?,
        None => PoseOverrides::default(),
    };
    let mut scan = scan::load(&args.scan, &args.frame.options()).map_err(Failure::bad_input)?;
    let export = args.export.export(&scan)?;
    scan.body.taubin_smooth(args.smooth.smooth);
    let file = scan.source.display().to_string();
    for w in scan.cleaning.warnings().into_iter().chain(topology(&scan.body).warnings()) {
        bar.suspend(|| warn(&file, &w));
    }
    let options =
        ReconstructOptions { pose, mannequin: args.mannequin.options(), ..Default::default() };
    let done = reconstruct(&scan, &model, &options, |step| {
        bar.inc(1);
        bar.set_message(STEPS.iter().chain(&pipeline::STEPS).nth(step).copied().unwrap_or(""));
    })
    .map_err(|e| Failure::bad_input(format!("{file}: {e}")))?;
    bar.inc(1);
    bar.set_message("writing");

    let fit_json = pretty_json(&done.fit_report())?;
    let mut outputs = OutputSet::new();
    let (posed, _) = export.place(&done.posed.body, &done.posed.frame);
    outputs.add(export.file_name("posed"), export.encode(&posed));
    let mannequin = done.result.mannequin_file(&export, &done.posed.frame);
    outputs.add(export.file_name("mannequin"), mannequin);
    outputs.add("rigged.glb", done.rigged_glb(&scan));
    let profiles = Profiles::of(&done.result.mannequin, &done.result.comparison.levels);
    outputs.add("profiles.json", pretty_json(&profiles)?);
    outputs.add("measurements.json", pretty_json(&done.measurements())?);
    outputs.add("fit.json", fit_json.clone());
    outputs.add(
        "preview.png",
        preview_png(&[(&scan.body, "scan"), (&done.posed.body, "pose-symmetric")], &done.result),
    );
    outputs.commit(&args.out).map_err(Failure::other)?;
    bar.finish_and_clear();
    if args.json {
        outln!("{fit_json}");
    } else {
        print_summary(&file, &done, args);
    }
    Ok(())
}

fn print_summary(file: &str, done: &Reconstruction, args: &ReconstructArgs) {
    outln!("{file}: pose-symmetric scan and mannequin written to {}", args.out.display());
    let worst = done.residuals.iter().map(|r| r.median_mm).fold(0.0, f64::max);
    outln!(
        "  fit: {} iterations, {:.1} s, worst region {:.1} mm from the scan (median)",
        done.fit.iterations,
        done.fit_seconds,
        worst
    );
    outln!("  {:<6} {:>12} {:>15} {:>12}", "", "scan (mm)", "pose-symm.", "mannequin");
    for row in &done.measurements().table {
        let scan = row.scan.map_or("-".to_string(), |g| format!("{:.1}", g.tape));
        outln!(
            "  {:<6} {:>12} {:>15.1} {:>12.1}",
            row.measure,
            scan,
            row.pose_symmetric.tape,
            row.mannequin.tape
        );
    }
    outln!("  (tape girths)");
}
