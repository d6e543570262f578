//! `dressform demo [--out DIR] [--seed N]`: the whole system on a built-in synthetic customer —
//! generate a body with known measurements (`sim`), scan it with a typical scanner's artifacts
//! (noise, holes, metres, Y up, turned), encode the scan as PLY and read it back, build the symmetric
//! mannequin, fit the reference form and drive the simulated form over the in-process bus —
//! then compare the customer's true girths with the scan's and the mannequin's.

use super::drive::{SimArgs, shape_verdict};
use super::run::{Drive, shape_form};
use super::{Failure, progress_bar};
use dressform::controller::{DriveOptions, LinkSpec};
use dressform::fitting::DEFAULT_GIRTH_TOLERANCE_MM;
use dressform::mesh::{Mesh, smooth::DEFAULT_PASSES};
use dressform::output::OutputSet;
use dressform::report::ScanInfo;
use dressform::scan::format::{Export, Format, Placement};
use dressform::scan::{self, frame::FrameOptions, frame::Units};
use glam::DVec3;
use sim::capture::{Artifacts, BodyParams, capture, generate};
use std::path::PathBuf;

#[derive(Debug, clap::Args)]
pub struct DemoArgs {
    /// Where to write the scan, the mannequin and the set-points.
    #[arg(long, default_value = "dressform-demo")]
    out: PathBuf,
    /// A different customer: random body measurements from this seed (default: a 1700 mm adult
    /// with chest 960, waist 800 and hip 1000 mm).
    #[arg(long)]
    seed: Option<u64>,
}

pub fn run(args: &DemoArgs) -> Result<(), Failure> {
    let bar = progress_bar(false, 3);
    let params = args.seed.map_or_else(BodyParams::default, BodyParams::random);
    bar.set_message("generating the customer");
    let customer = generate(&params).map_err(Failure::other)?;
    bar.inc(1);
    bar.set_message("scanning");
    let artifacts = Artifacts::typical_scanner(args.seed.unwrap_or(0));
    let raw = capture(&customer, &artifacts);
    let raw =
        Mesh::new(raw.positions.iter().map(|&p| DVec3::from_array(p)).collect(), raw.triangles);
    let scanner = Placement::AsIs {
        units: Units::M,
        frame: format!("the scanner's: Y up, turned {} degrees", artifacts.yaw_deg),
    };
    let scan_file = Export::new(Format::Ply, scanner).map_err(Failure::other)?.encode(&raw);
    let scan_path = args.out.join("scan.ply");
    bar.inc(1);
    bar.set_message("reading the scan back");
    let mut scan = scan::from_bytes(&scan_file, &scan_path, &FrameOptions::default())
        .map_err(Failure::bad_input)?;
    let mut outputs = OutputSet::new();
    outputs.add("scan.ply", scan_file);
    let info = ScanInfo::new(&scan);
    scan.body.taubin_smooth(DEFAULT_PASSES);
    bar.finish_and_clear();

    let truth = &customer.truth;
    outln!(
        "A synthetic customer: {:.0} mm tall, chest {:.0}, waist {:.0}, hip {:.0} mm, crotch height {:.0} mm.",
        truth.height_mm,
        truth.chest.tape_girth_mm,
        truth.waist.tape_girth_mm,
        truth.hip.tape_girth_mm,
        truth.crotch_height_mm
    );
    outln!(
        "Scanned with {:.1} mm noise, holes at the armpits, crotch and soles, in metres, Y up, turned {:.0} degrees:",
        artifacts.noise_sigma_mm,
        artifacts.yaw_deg
    );
    out!("{info}");
    outln!();
    let drive = Drive {
        link: &LinkSpec::Sim,
        sim: &SimArgs::default(),
        options: &DriveOptions::default(),
        girth_tolerance: DEFAULT_GIRTH_TOLERANCE_MM,
    };
    let (result, shape) =
        shape_form(&scan, &form_description::reference(), &drive, &args.out, outputs)?;
    outln!();
    outln!("  {:<12} {:>9} {:>9} {:>11}", "measure (mm)", "customer", "scan", "mannequin");
    let c = &result.comparison;
    outln!("  {:<12} {:>9.1} {:>9.1} {:>11}", "height", truth.height_mm, c.input.height, "-");
    for (row, asked) in c.table.iter().zip([truth.chest, truth.waist, truth.hip]) {
        outln!(
            "  {:<12} {:>9.1} {:>9.1} {:>11.1}",
            row.measure,
            asked.tape_girth_mm,
            row.input.tape,
            row.mannequin.tape
        );
    }
    outln!();
    outln!(
        "Written to {}: scan.ply, mannequin.obj, profiles.json, measurements.json, setpoints.json, preview.png (a picture of the scan and the mannequin), sections.svg",
        args.out.display()
    );
    shape_verdict(&shape)
}
