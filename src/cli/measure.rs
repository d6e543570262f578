//! `dressform measure <mesh> [--json] [--at z,...]`.

use super::{Failure, FrameArgs, SmoothArgs, warn};
use dressform::measure::{Girth, Levels, Measurements, levels, measure_at};
use dressform::regions::{BodyRegions, Landmarks, TRACKING_STEP_MM};
use dressform::scan;
use serde::Serialize;
use std::path::PathBuf;

#[derive(Debug, clap::Args)]
pub struct MeasureArgs {
    /// The body: an .obj, .ply or .stl file.
    mesh: PathBuf,
    /// Also give the torso girth at these heights (mm above the floor), comma-separated.
    #[arg(long, value_delimiter = ',')]
    at: Vec<f64>,
    /// Print JSON (documented in the README).
    #[arg(long)]
    json: bool,
    #[command(flatten)]
    frame: FrameArgs,
    #[command(flatten)]
    smooth: SmoothArgs,
}

#[derive(Serialize)]
struct MeasureOut {
    file: String,
    landmarks: Landmarks,
    levels: Levels,
    measurements: Measurements,
    /// Torso girths at the requested heights (`null` where there is no torso).
    at: Vec<Option<Girth>>,
}

pub fn run(args: &MeasureArgs) -> Result<(), Failure> {
    if let Some(h) = args.at.iter().find(|h| !h.is_finite()) {
        return Err(Failure::bad_input(format!("--at: {h} is not a height")));
    }
    let mut scan = scan::load(&args.mesh, &args.frame.options()).map_err(Failure::bad_input)?;
    scan.body.taubin_smooth(args.smooth.smooth);
    let file = scan.source.display().to_string();
    for w in scan.cleaning.warnings() {
        warn(&file, &w);
    }
    let regions = BodyRegions::find(&scan.body, TRACKING_STEP_MM)
        .map_err(|e| Failure::bad_input(format!("{file}: {e}")))?;
    let levels = levels(&scan.body, &regions);
    let measurements = measure_at(&scan.body, &regions, &levels);
    let at = regions
        .torso_sections(&scan.body, &args.at)
        .into_iter()
        .zip(&args.at)
        .map(|(l, &z)| l.map(|c| Girth { z, tape: c.tape_girth(), contour: c.perimeter() }))
        .collect();
    let out = MeasureOut { file, landmarks: regions.landmarks, levels, measurements, at };
    if args.json {
        outln!("{}", serde_json::to_string_pretty(&out).map_err(Failure::other)?);
        return Ok(());
    }
    let m = &out.measurements;
    outln!("{}", out.file);
    outln!("  height          {:7.1} mm", m.height);
    outln!("  crotch height   {:7.1} mm", m.crotch_height);
    for (name, g) in [("chest", m.chest), ("waist", m.waist), ("hip", m.hip)] {
        outln!(
            "  {name:<6} girth    {:7.1} mm at z = {:.0} mm (contour {:.1} mm)",
            g.tape,
            g.z,
            g.contour
        );
    }
    for (z, g) in args.at.iter().zip(&out.at) {
        match g {
            Some(g) => {
                outln!("  torso at {z:.0} mm  {:7.1} mm (contour {:.1} mm)", g.tape, g.contour)
            }
            None => outln!("  torso at {z:.0} mm  none"),
        }
    }
    Ok(())
}
