//! `dressform reconstruct <scan> -o <dir> [--model model.glb] [--pose pose.toml]
//! [--format ...] [--units ...] [--up ...] [--scan-frame] [--json] [--report PATH]`: pose
//! symmetry, then the mannequin (see [`dressform::run::reconstruct`]).

use super::symmetrize::pretty_json;
use super::{
    ExportArgs, Failure, MannequinArgs, ReportArgs, ScanFrameArgs, SmoothArgs, print_warnings,
    progress_bar,
};
use dressform::body::mesh::decimate::WORKING_TRIANGLES;
use dressform::body::scan::{self, ScanOptions};
use dressform::pose::body_model::BodyModel;
use dressform::pose::pose_symmetry::PoseOverrides;
use dressform::run::outputs::Outputs;
use dressform::run::pipeline;
use dressform::run::reconstruct::{
    MeasurementsReport, ReconstructOptions, Reconstruction, STEPS, reconstruct,
};
use std::path::{Path, PathBuf};

#[derive(Debug, clap::Args)]
pub struct ReconstructArgs {
    /// The scan: an .obj, .ply or .stl file.
    scan: PathBuf,
    /// Output directory (created if missing): posed.obj and mannequin.obj (or .ply, .stl,
    /// .glb), rigged.glb, profiles.json, measurements.json, fit.json, preview.png,
    /// sections.svg, report.html, replaced as a whole.
    #[arg(short, long)]
    out: PathBuf,
    /// The body model (.glb) [default: the built-in model].
    #[arg(long)]
    model: Option<PathBuf>,
    /// Joint angles to set on the symmetric pose (TOML; see docs/formats.md).
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
    #[command(flatten)]
    report: ReportArgs,
}

pub fn run(args: &ReconstructArgs) -> Result<(), Failure> {
    let steps = STEPS.len() + pipeline::STEPS.len();
    let bar = progress_bar(args.json, steps as u64 + 2);
    bar.set_message("reading the scan");
    let model = super::model::load(args.model.as_deref())?;
    let pose = pose_overrides(args.pose.as_deref(), &model)?;
    let options = ScanOptions {
        frame: args.frame.options(),
        smooth: args.smooth.smooth,
        max_triangles: Some(WORKING_TRIANGLES),
    };
    let scan::PreparedScan { scan, warnings, .. } =
        scan::prepare(&args.scan, &options).map_err(Failure::bad_input)?;
    let export = args.export.export(&scan)?;
    let file = scan.source.display().to_string();
    print_warnings(&file, &warnings, Some(&bar));
    let options =
        ReconstructOptions { pose, mannequin: args.mannequin.options(), ..Default::default() };
    let done = reconstruct(&scan, &model, &options, |step| {
        bar.inc(1);
        bar.set_message(STEPS.iter().chain(&pipeline::STEPS).nth(step).copied().unwrap_or(""));
    })
    .map_err(|e| Failure::bad_input(scan.failed(e)))?;
    bar.inc(1);
    bar.set_message("writing");

    let outputs = Outputs::reposed(&done.result, &done.reposed, &done.as_scanned, &scan, &export);
    args.report.commit(outputs.files().map_err(Failure::other)?, &args.out)?;
    bar.finish_and_clear();
    if args.json {
        outln!("{}", pretty_json(&done.reposed.fit_report())?);
    } else {
        print_summary(&file, &done, args);
    }
    Ok(())
}

/// The joint angles of `--pose` for `model`'s skeleton, or none.
pub(super) fn pose_overrides(
    path: Option<&Path>,
    model: &BodyModel,
) -> Result<PoseOverrides, Failure> {
    match path {
        Some(path) => PoseOverrides::load(path, &model.skeleton).map_err(Failure::bad_input),
        None => Ok(PoseOverrides::default()),
    }
}

fn print_summary(file: &str, done: &Reconstruction, args: &ReconstructArgs) {
    outln!("{file}: pose-symmetric scan and mannequin written to {}", args.out.display());
    let reposed = &done.reposed;
    let worst = reposed.residuals.iter().map(|r| r.median_mm).fold(0.0, f64::max);
    outln!(
        "  fit: {} iterations, {:.1} s, worst region {:.1} mm from the scan (median)",
        reposed.fit.iterations,
        reposed.fit_seconds,
        worst
    );
    outln!("  {:<6} {:>12} {:>15} {:>12}", "", "scan (mm)", "pose-symm.", "mannequin");
    for row in &MeasurementsReport::new(&done.as_scanned, &done.result.comparison).table {
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
