//! `dressform symmetrize <scan> -o <dir> [--torso-layers N] [--leg-layers N] [--rays N]
//! [--preserve tape|contour] [--format obj|ply|stl|glb] [--units mm|cm|m] [--up z|y]
//! [--scan-frame] [--json] [--report PATH]`.

use super::{
    ExportArgs, Failure, MannequinArgs, ReportArgs, ScanFrameArgs, SmoothArgs, print_warnings,
    progress_bar,
};
use dressform::body::mesh::decimate::WORKING_TRIANGLES;
use dressform::body::scan::{self, ScanOptions};
use dressform::run::outputs::Outputs;
use dressform::run::pipeline::{STEPS, symmetrize};
use dressform::shape::mannequin::MannequinError;
use dressform::shape::measure::{Comparison, stance};
use std::path::PathBuf;

#[derive(Debug, clap::Args)]
pub struct SymmetrizeArgs {
    /// The scan: an .obj, .ply or .stl file.
    scan: PathBuf,
    /// Output directory (created if missing): mannequin.obj (or .ply, .stl, .glb),
    /// profiles.json, measurements.json, preview.png, sections.svg, report.html, replaced as a
    /// whole.
    #[arg(short, long)]
    out: PathBuf,
    #[command(flatten)]
    mannequin: MannequinArgs,
    #[command(flatten)]
    export: ExportArgs,
    /// Print measurements.json to standard output instead of the table.
    #[arg(long)]
    json: bool,
    #[command(flatten)]
    frame: ScanFrameArgs,
    #[command(flatten)]
    smooth: SmoothArgs,
    #[command(flatten)]
    report: ReportArgs,
}

/// What a failed `symmetrize` adds for a scan whose stance it could not take apart.
const RECONSTRUCT_HINT: &str = "; symmetrize takes a scan in the A-pose (arms out, feet apart, \
     trunk upright): `dressform reconstruct` re-poses a scan in any other stance first";

pub fn run(args: &SymmetrizeArgs) -> Result<(), Failure> {
    let bar = progress_bar(args.json, STEPS.len() as u64 + 2);
    bar.set_message("reading the scan");
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
    let options = args.mannequin.options();
    let result = symmetrize(&scan, &options, |step| {
        bar.inc(1);
        bar.set_message(STEPS[step]);
    })
    .map_err(|e| {
        // A stance the segmentation cannot take apart: `reconstruct` re-poses it first.
        let posed = !matches!(e, MannequinError::TooFewLayers { .. });
        let hint = if posed { RECONSTRUCT_HINT } else { "" };
        Failure::bad_input(format!("{file}: {e}{hint}"))
    })?;
    print_warnings(&file, &stance::warnings(&result.regions.landmarks), Some(&bar));
    bar.inc(1);
    bar.set_message("writing");

    let outputs = Outputs::of(&result, &scan, &export).files().map_err(Failure::other)?;
    args.report.commit(outputs, &args.out)?;
    bar.finish_and_clear();
    if args.json {
        outln!("{}", pretty_json(&result.comparison)?);
    } else {
        print_table(&file, &result.comparison, &args.out);
    }
    Ok(())
}

pub(super) fn pretty_json(value: &impl serde::Serialize) -> Result<String, Failure> {
    serde_json::to_string_pretty(value).map_err(Failure::other)
}

fn print_table(file: &str, c: &Comparison, out: &std::path::Path) {
    outln!("{file}: symmetric mannequin written to {}", out.display());
    outln!("  {:<6} {:>8} {:>12} {:>12} {:>9}", "", "z (mm)", "input (mm)", "mannequin", "change");
    for row in &c.table {
        outln!(
            "  {:<6} {:>8.0} {:>12.1} {:>12.1} {:>+9.2}",
            row.measure,
            row.z,
            row.input.tape,
            row.mannequin.tape,
            row.tape_change_mm
        );
    }
    outln!(
        "  (tape girths; height {:.0} mm, crotch height {:.0} mm)",
        c.input.height,
        c.input.crotch_height
    );
    outln!("  {:<15} {:>10} {:>8} {:>8} {:>8}", "Fig. 11", "hip width", "chest", "waist", "hip");
    for r in &c.mirrored {
        outln!(
            "  {:<15} {:>10.1} {:>8.1} {:>8.1} {:>8.1}",
            r.body,
            r.hip_width,
            r.chest,
            r.waist,
            r.hip
        );
    }
}
