//! `dressform measure <mesh or directory>... [--json | --csv] [--at z,...]`: one scan, or
//! several measured in parallel (one row each).

use super::{Failure, FrameArgs, SmoothArgs, print_warnings, warn};
use dressform::body::scan::{self, ScanOptions};
use dressform::shape::measure::{MeasureReport, measure_scan};
use rayon::prelude::*;
use std::path::{Path, PathBuf};

#[derive(Debug, clap::Args)]
pub struct MeasureArgs {
    /// The bodies: .obj, .ply or .stl files, or directories of them.
    #[arg(required = true)]
    meshes: Vec<PathBuf>,
    /// Also give the torso girth at these heights (mm above the floor), comma-separated.
    #[arg(long, value_delimiter = ',')]
    at: Vec<f64>,
    /// Print JSON (documented in docs/measurements.md): an object, or an array for several scans.
    #[arg(long, conflicts_with = "csv")]
    json: bool,
    /// Print CSV for spreadsheets: a header line, then one row per scan.
    #[arg(long)]
    csv: bool,
    #[command(flatten)]
    frame: FrameArgs,
    #[command(flatten)]
    smooth: SmoothArgs,
}

/// The scan files `paths` name: files as given, directories' .obj, .ply and .stl files.
fn scan_files(paths: &[PathBuf]) -> Result<Vec<PathBuf>, Failure> {
    let scan = |p: &Path| scan::format::Format::from_path(p).is_some();
    super::files_in(paths, scan, ".obj, .ply or .stl file")
}

/// Reads, prepares (see [`scan::prepare`]) and measures one scan; its scan's warnings are
/// printed as it is read.
fn measure_one(path: &Path, args: &MeasureArgs) -> Result<MeasureReport, Failure> {
    let options = ScanOptions {
        frame: args.frame.options(),
        smooth: args.smooth.smooth,
        max_triangles: None,
    };
    let prepared = scan::prepare(path, &options).map_err(Failure::bad_input)?;
    let file = prepared.scan.source.display().to_string();
    print_warnings(&file, &prepared.warnings, None);
    measure_scan(&prepared.scan, &args.at).map_err(|e| Failure::bad_input(format!("{file}: {e}")))
}

/// The scalar fields of a JSON object, flattened to `a.b` names, in order.
fn flatten(prefix: &str, v: &serde_json::Value, out: &mut Vec<(String, String)>) {
    match v {
        serde_json::Value::Object(map) => {
            for (k, v) in map {
                let name = if prefix.is_empty() { k.clone() } else { format!("{prefix}.{k}") };
                flatten(&name, v, out);
            }
        }
        serde_json::Value::Number(n) => {
            let x = n.as_f64().unwrap_or(f64::NAN);
            out.push((prefix.to_string(), format!("{x:.1}")));
        }
        // A measurement not taken (an arm raised too high): an empty cell keeps the columns.
        serde_json::Value::Null => out.push((prefix.to_string(), String::new())),
        _ => {}
    }
}

/// One CSV row of a scan: its file and every dimension.
fn csv_row(m: &MeasureReport) -> Result<Vec<(String, String)>, Failure> {
    let mut row = vec![("file".to_string(), format!("\"{}\"", m.file.replace('"', "\"\"")))];
    let dims = serde_json::to_value(&m.dimensions).map_err(Failure::other)?;
    flatten("", &dims, &mut row);
    Ok(row)
}

fn print_text(m: &MeasureReport, at: &[f64]) {
    let d = &m.dimensions;
    outln!("{}", m.file);
    let g = |name: &str, v: f64| {
        if v.is_nan() {
            // A fold or landmark the body does not show (docs/measurements.md, "The measurement set").
            outln!("  {name:<22} not measured")
        } else {
            outln!("  {name:<22} {v:7.1} mm")
        }
    };
    let b = |name: &str, v: &dressform::shape::measure::Bilateral, unit: &str| {
        if v.difference.is_nan() {
            // An arm raised too high to be followed down its loops, or a side held back as
            // implausible (the warnings say why).
            let side = |x: f64| if x.is_nan() { "-".to_string() } else { format!("{x:.1}") };
            outln!(
                "  {name:<22} not measured (left {}, right {} {unit})",
                side(v.left),
                side(v.right)
            )
        } else {
            outln!(
                "  {name:<22} {:7.1} {unit} left, {:7.1} {unit} right ({:+.1})",
                v.left,
                v.right,
                v.difference
            )
        }
    };
    g("stature", d.stature_mm);
    g("neck girth", d.neck_girth_mm);
    g("neck-base girth", d.neck_base_girth_mm);
    g("shoulder width", d.shoulder_width_mm);
    g("across shoulder", d.across_shoulder_mm);
    b("shoulder slope", &d.shoulder_slope_deg, "deg");
    g("across back", d.across_back_mm);
    g("across front", d.across_front_mm);
    let at_level = |name: &str, tape: f64, z: f64, contour: Option<f64>| {
        let contour = contour.map(|c| format!(" (contour {c:.1} mm)")).unwrap_or_default();
        if tape.is_nan() || z.is_nan() {
            outln!("  {name:<22} not measured")
        } else {
            outln!("  {name:<22} {tape:7.1} mm at z = {z:.0} mm{contour}")
        }
    };
    let (bust, waist, hip) = (m.measurements.chest, m.measurements.waist, m.measurements.hip);
    at_level("chest girth", d.chest_girth_mm, d.chest_height_mm, None);
    at_level("bust girth", d.bust_girth_mm, bust.z, Some(bust.contour));
    at_level("waist girth", d.waist_girth_mm, waist.z, Some(waist.contour));
    at_level("hip girth", d.hip_girth_mm, hip.z, Some(hip.contour));
    g("underbust girth", d.underbust_girth_mm);
    g("high hip girth", d.high_hip_girth_mm);
    b("thigh girth", &d.thigh_girth_mm, "mm");
    b("knee girth", &d.knee_girth_mm, "mm");
    b("calf girth", &d.calf_girth_mm, "mm");
    b("ankle girth", &d.ankle_girth_mm, "mm");
    b("upper-arm girth", &d.upper_arm_girth_mm, "mm");
    b("wrist girth", &d.wrist_girth_mm, "mm");
    b("arm length", &d.arm_length_mm, "mm");
    g("inside leg", d.inside_leg_mm);
    g("back waist length", d.back_waist_length_mm);
    g("front waist length", d.front_waist_length_mm);
    for (z, g) in at.iter().zip(&m.at) {
        match g {
            Some(g) => {
                outln!("  torso at {z:.0} mm  {:7.1} mm (contour {:.1} mm)", g.tape, g.contour)
            }
            None => outln!("  torso at {z:.0} mm  none"),
        }
    }
}

pub fn run(args: &MeasureArgs) -> Result<(), Failure> {
    if let Some(h) = args.at.iter().find(|h| !h.is_finite()) {
        return Err(Failure::bad_input(format!("--at: {h} is not a height")));
    }
    let files = scan_files(&args.meshes)?;
    let results: Vec<Result<MeasureReport, Failure>> =
        files.par_iter().map(|f| measure_one(f, args)).collect();
    // Every scan is measured; the first that failed decides the exit status.
    let mut done = Vec::with_capacity(results.len());
    let mut failed = Vec::new();
    for r in results {
        match r {
            Ok(m) => done.push(m),
            Err(e) if files.len() == 1 => return Err(e),
            Err(e) => {
                errln!("error: {}", e.message);
                failed.push(e.exit_code);
            }
        }
    }
    for m in &done {
        for w in &m.warnings {
            warn(&m.file, w);
        }
    }
    if args.json {
        let text = if files.len() == 1 {
            serde_json::to_string_pretty(&done[0])
        } else {
            serde_json::to_string_pretty(&done)
        };
        outln!("{}", text.map_err(Failure::other)?);
    } else if args.csv {
        let rows: Vec<Vec<(String, String)>> =
            done.iter().map(csv_row).collect::<Result<_, _>>()?;
        if let Some(first) = rows.first() {
            outln!("{}", first.iter().map(|(k, _)| k.as_str()).collect::<Vec<_>>().join(","));
        }
        for row in &rows {
            outln!("{}", row.iter().map(|(_, v)| v.as_str()).collect::<Vec<_>>().join(","));
        }
    } else {
        for m in &done {
            print_text(m, &args.at);
        }
    }
    match failed.first() {
        None => Ok(()),
        Some(&exit_code) => Err(Failure {
            message: format!("{} of {} scans could not be measured", failed.len(), files.len()),
            exit_code,
        }),
    }
}
