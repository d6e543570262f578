//! `dressform info <scan> [--json]`.

use super::{Failure, FrameArgs, warn};
use dressform::body::scan;
use dressform::run::info::ScanInfo;
use std::path::PathBuf;

#[derive(Debug, clap::Args)]
pub struct InfoArgs {
    /// The scan: an .obj, .ply or .stl file.
    scan: PathBuf,
    /// Print the report as JSON (documented in docs/formats.md).
    #[arg(long)]
    json: bool,
    #[command(flatten)]
    frame: FrameArgs,
}

pub fn run(args: &InfoArgs) -> Result<(), Failure> {
    let scan = scan::load(&args.scan, &args.frame.options()).map_err(Failure::bad_input)?;
    let info = ScanInfo::new(&scan);
    for w in &info.warnings {
        warn(&info.file, w);
    }
    if args.json {
        outln!("{}", serde_json::to_string_pretty(&info).map_err(Failure::other)?);
    } else {
        out!("{info}");
    }
    Ok(())
}
