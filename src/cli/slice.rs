//! `dressform slice <mesh> --heights 900,950,... [--json]`.

use super::{Failure, FrameArgs, print_warnings, warn};
use dressform::body::regions::{BodyRegions, Region, TRACKING_STEP_MM};
use dressform::body::scan::{self, ScanOptions};
use dressform::body::slice::sections;
use rayon::prelude::*;
use serde::Serialize;
use std::path::PathBuf;

#[derive(Debug, clap::Args)]
pub struct SliceArgs {
    /// The mesh: an .obj, .ply or .stl file.
    mesh: PathBuf,
    /// Heights of the cutting planes in mm above the floor (canonical frame), comma-separated.
    #[arg(long, value_delimiter = ',', required = true)]
    heights: Vec<f64>,
    /// Print JSON (documented in docs/measurements.md).
    #[arg(long)]
    json: bool,
    #[command(flatten)]
    frame: FrameArgs,
    /// Taubin smoothing passes applied before cutting, 0 to 100 (default 0: the scan as it
    /// is; the commands that measure use 8). A mannequin dressform made is never smoothed.
    #[arg(long, default_value_t = 0, value_parser = super::passes_parser())]
    smooth: usize,
}

#[derive(Serialize)]
struct LoopOut {
    label: Option<Region>,
    perimeter_mm: f64,
    tape_girth_mm: f64,
    centroid_mm: [f64; 2],
    points: usize,
}

#[derive(Serialize)]
struct SectionOut {
    z_mm: f64,
    bridged_gaps: usize,
    loops: Vec<LoopOut>,
}

#[derive(Serialize)]
struct SliceOut {
    file: String,
    sections: Vec<SectionOut>,
}

pub fn run(args: &SliceArgs) -> Result<(), Failure> {
    if let Some(h) = args.heights.iter().find(|h| !h.is_finite()) {
        return Err(Failure::bad_input(format!("--heights: {h} is not a height")));
    }
    let options =
        ScanOptions { frame: args.frame.options(), smooth: args.smooth, max_triangles: None };
    // The scan's topology is checked beside the segmentation's tracking (or the sections).
    let (prepared, (regions, sections)) =
        scan::prepare_then(&args.mesh, &options, |scan, check| {
            match &scan.carried {
                // A mannequin dressform made: labelled by the landmarks its file carries.
                Some(carried) => {
                    let (cut, checked) =
                        rayon::join(|| sections(&scan.body, &args.heights), || check.run());
                    ((Ok(BodyRegions::armless(carried.landmarks)), cut), checked)
                }
                None => {
                    let (regions, cut, checked) = BodyRegions::find_and_cut_beside(
                        &scan.body,
                        TRACKING_STEP_MM,
                        &args.heights,
                        || check.run(),
                    );
                    ((regions, cut), checked)
                }
            }
        })
        .map_err(Failure::bad_input)?;
    let file = prepared.scan.source.display().to_string();
    print_warnings(&file, &prepared.warnings, None);
    let regions = regions.map_err(|e| warn(&file, &format!("loops are not labelled: {e}"))).ok();
    for s in sections.iter().filter(|s| s.bridged_gaps > 0) {
        warn(
            &file,
            &format!(
                "closed {} open loops at z = {:.1} mm (holes in the scan)",
                s.bridged_gaps, s.height
            ),
        );
    }
    let out = SliceOut {
        file: file.clone(),
        sections: sections
            .into_par_iter()
            .map(|s| {
                let labels = regions.as_ref().map(|r| r.label(&s));
                SectionOut {
                    z_mm: s.height,
                    bridged_gaps: s.bridged_gaps,
                    loops: s
                        .loops
                        .iter()
                        .enumerate()
                        .map(|(k, l)| LoopOut {
                            label: labels.as_ref().map(|ls| ls[k]),
                            perimeter_mm: l.perimeter(),
                            tape_girth_mm: l.tape_girth(),
                            centroid_mm: l.centroid().to_array(),
                            points: l.points.len(),
                        })
                        .collect(),
                }
            })
            .collect(),
    };
    let gaps: Vec<&SectionOut> = out.sections.iter().filter(|s| s.bridged_gaps > 0).collect();
    if !gaps.is_empty() {
        let total: usize = gaps.iter().map(|s| s.bridged_gaps).sum();
        warn(
            &file,
            &format!(
                "closed {total} open loops on {} of {} planes (holes in the scan; see bridged_gaps per plane)",
                gaps.len(),
                out.sections.len()
            ),
        );
    }
    if args.json {
        outln!("{}", serde_json::to_string_pretty(&out).map_err(Failure::other)?);
        return Ok(());
    }
    outln!("{file}");
    for s in &out.sections {
        outln!("  z = {:.1} mm: {} loops", s.z_mm, s.loops.len());
        for l in &s.loops {
            let label = l.label.map_or("unlabelled", |r| r.name());
            outln!(
                "    {label:<10} contour {:8.1} mm  tape girth {:8.1} mm  at ({:.0}, {:.0})",
                l.perimeter_mm,
                l.tape_girth_mm,
                l.centroid_mm[0],
                l.centroid_mm[1]
            );
        }
    }
    Ok(())
}
