//! Command-line arguments and dispatch. Each command lives in its own module.

/// `print!` for a command's output, through [`write_out`]: it never panics when standard
/// output fails.
macro_rules! out {
    ($($arg:tt)*) => {
        $crate::cli::write_out(format_args!($($arg)*))
    };
}

/// `println!` for a command's output (see [`out!`]).
macro_rules! outln {
    () => {
        $crate::cli::write_out(format_args!("\n"))
    };
    ($($arg:tt)*) => {
        $crate::cli::write_out(format_args!("{}\n", format_args!($($arg)*)))
    };
}

/// `eprintln!` through [`write_err`]: it never panics when standard error fails.
macro_rules! errln {
    ($($arg:tt)*) => {
        $crate::cli::write_err(format_args!("{}\n", format_args!($($arg)*)))
    };
}

mod batch;
#[cfg(feature = "simulator")]
mod demo;
mod drive;
mod estop;
mod fit_test;
mod form;
mod info;
mod link;
mod measure;
mod model;
mod reconstruct;
mod reset;
mod run;
mod setpoints;
mod signals;
#[cfg(feature = "simulator")]
mod sim;
mod slice;
mod status;
mod symmetrize;
mod watch;

// Without the simulator: `demo` and `sim` still parse, and refuse.
#[cfg(not(feature = "simulator"))]
mod no_simulator;
#[cfg(not(feature = "simulator"))]
use no_simulator::{demo, sim};

use clap::builder::{PossibleValue, PossibleValuesParser, RangedU64ValueParser, TypedValueParser};
use clap::{Parser, Subcommand};
use dressform::atomic_output::{OutputSet, write_atomically};
use dressform::body::mesh::smooth;
use dressform::body::scan::Scan;
use dressform::body::scan::format::{Export, Format, Placement, UpAxis};
use dressform::body::scan::frame::{Direction, FrameOptions, Units};
use dressform::messages;
use dressform::run::outputs::REPORT;
use dressform::shape::mannequin::{LegStance, MannequinOptions, StopAt};
use dressform::shape::symmetry::Preserve;
use std::io::{ErrorKind, Write};
use std::ops::{Bound, RangeBounds};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};

/// Personalized symmetric mannequins from 3D body scans, and the robotic dress form they drive.
#[derive(Debug, Parser)]
#[command(name = "dressform", version, about)]
pub struct Args {
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Describe a scan: counts, units, up axis, facing, height, components, holes, manifoldness.
    Info(info::InfoArgs),
    /// Cut a mesh by horizontal planes: each loop's label, contour length and tape girth.
    Slice(slice::SliceArgs),
    /// Measure a body: height, crotch height, chest, waist and hip girths and their levels.
    Measure(measure::MeasureArgs),
    /// Build the symmetric mannequin of a scan: mannequin.obj, profiles.json, measurements.json.
    Symmetrize(symmetrize::SymmetrizeArgs),
    /// Pose symmetry, then the mannequin: fit the body model, re-pose the scan symmetric, build.
    Reconstruct(reconstruct::ReconstructArgs),
    /// Compute the actuator set-points that give the robotic form a mannequin's shape.
    Setpoints(setpoints::SetpointsArgs),
    /// Scan to shaped form in one command: mannequin, set-points, drive, girth report.
    Run(run::RunArgs),
    /// Start a simulated robotic form on a pseudo-terminal and print its device path.
    Sim(sim::ServeArgs),
    /// Run the pipeline on a built-in synthetic customer, no files or hardware needed.
    Demo(demo::DemoArgs),
    /// Drive the robotic form to a set-point file, all actuators together, with live progress.
    Drive(drive::DriveArgs),
    /// Test a garment on the form shaped to a customer: ease and pressure per ring, a sweep.
    FitTest(fit_test::FitTestArgs),
    /// Show every node of the robotic form: identity, state, faults, positions.
    Status(status::StatusArgs),
    /// Broadcast an emergency stop to every node of the robotic form, from any terminal.
    Estop(estop::EstopArgs),
    /// The statistical body model: build it, describe it, sample bodies from it.
    Model(model::ModelArgs),
    /// Clear the latched faults of every node (FaultReset), saying what each held.
    Reset(reset::ResetArgs),
    /// The robotic form's description: `form show [--toml]`.
    Form(form::FormArgs),
    /// Process every scan of a folder or manifest into OUT/<customer>/, with a summary.csv;
    /// sharded across cluster jobs with --shard or Slurm's and Kubernetes' variables.
    Batch(batch::BatchArgs),
    /// Join the summaries of a batch's shards into one.
    BatchMerge(batch::MergeArgs),
    /// Watch a folder: each scan that lands is processed into OUT/<its name>/.
    Watch(watch::WatchArgs),
}

/// How the scan's frame is given on the command line (all optional: detected by default).
#[derive(Debug, Clone, clap::Args)]
pub struct FrameArgs {
    /// The scan's length unit [default: detected from the body's height].
    #[arg(long, value_parser = units_parser())]
    units: Option<Units>,
    /// The scan's up axis: x, y, z, -x, -y or -z [default: detected].
    #[arg(long, allow_hyphen_values = true)]
    up: Option<Direction>,
    /// The axis the subject faces in the scan: x, y, z, -x, -y or -z [default: detected].
    #[arg(long, allow_hyphen_values = true)]
    facing: Option<Direction>,
}

/// Denoising before measuring.
#[derive(Debug, Clone, clap::Args)]
pub struct SmoothArgs {
    /// Taubin smoothing passes applied to the scan before measuring, 0 (none) to 100. Scanner
    /// noise otherwise inflates tape girths by several millimetres.
    #[arg(long, default_value_t = smooth::DEFAULT_PASSES, value_parser = passes_parser())]
    smooth: usize,
}

/// `--smooth`: 0 to [`smooth::MAX_PASSES`] passes.
fn passes_parser() -> RangedU64ValueParser<usize> {
    RangedU64ValueParser::new().range(0..=smooth::MAX_PASSES as u64)
}

/// A parser for one of the library's plain enums (the library knows nothing of clap): each of
/// `all` is taken by its `name`, and listed in `--help` with its `help` line.
fn named<T: Copy + Send + Sync + 'static, const N: usize>(
    all: [T; N],
    name: fn(T) -> &'static str,
    help: fn(T) -> &'static str,
) -> impl TypedValueParser<Value = T> {
    let values = all.map(|v| PossibleValue::new(name(v)).help(help(v)));
    PossibleValuesParser::new(values)
        .map(move |s| all.into_iter().find(|&v| name(v) == s).expect("one of the possible values"))
}

/// `--units` of a scan: the library's [`Units`] by symbol.
fn units_parser() -> impl TypedValueParser<Value = Units> {
    named(Units::ALL, Units::symbol, |u| match u {
        Units::M => "Metres",
        Units::Dm => "Decimetres (MakeHuman)",
        Units::Cm => "Centimetres",
        Units::Mm => "Millimetres",
        Units::In => "Inches",
    })
}

/// `--preserve`: the library's [`Preserve`] by name.
fn preserve_parser() -> impl TypedValueParser<Value = Preserve> {
    named(Preserve::ALL, Preserve::name, |p| match p {
        Preserve::Tape => "The tape girth (the convex hull's perimeter): what a tailor measures",
        Preserve::Contour => "The contour's own length: the paper's literal rule",
    })
}

impl FrameArgs {
    fn options(&self) -> FrameOptions {
        FrameOptions { units: self.units, up: self.up, facing: self.facing }
    }
}

/// The scan's frame in commands that also write a mesh (whose own `--units` and `--up` are in
/// [`ExportArgs`]).
#[derive(Debug, Clone, clap::Args)]
pub struct ScanFrameArgs {
    /// The scan's length unit [default: detected from the body's height].
    #[arg(long, value_parser = units_parser())]
    scan_units: Option<Units>,
    /// The scan's up axis: x, y, z, -x, -y or -z [default: detected].
    #[arg(long, allow_hyphen_values = true)]
    scan_up: Option<Direction>,
    /// The axis the subject faces in the scan: x, y, z, -x, -y or -z [default: detected].
    #[arg(long, allow_hyphen_values = true)]
    scan_facing: Option<Direction>,
}

impl ScanFrameArgs {
    fn options(&self) -> FrameOptions {
        FrameOptions { units: self.scan_units, up: self.scan_up, facing: self.scan_facing }
    }
}

/// How a command builds the mannequin.
#[derive(Debug, Clone, clap::Args)]
pub struct MannequinArgs {
    /// Torso layers.
    #[arg(long, default_value_t = 100)]
    torso_layers: usize,
    /// Leg layers.
    #[arg(long, default_value_t = 50)]
    leg_layers: usize,
    /// Rays per section (even).
    #[arg(long, default_value_t = 360)]
    rays: usize,
    /// The girth every layer keeps: tape (convex hull) or contour (the paper's rule).
    #[arg(long, value_parser = preserve_parser(), default_value = Preserve::Tape.name())]
    preserve: Preserve,
    #[command(flatten)]
    legs: LegArgs,
}

impl MannequinArgs {
    fn options(&self) -> MannequinOptions {
        MannequinOptions {
            torso_layers: self.torso_layers,
            leg_layers: self.leg_layers,
            rays: self.rays,
            preserve: self.preserve,
            ..self.legs.options()
        }
    }
}

/// How the mannequin's legs stand and where they end: `symmetrize`, `reconstruct`, `run` and
/// `demo` take these.
#[derive(Debug, Clone, clap::Args)]
pub struct LegArgs {
    /// How the legs stand.
    #[arg(long, value_parser = stance_parser(), default_value = LegStance::Straight.name())]
    legs: LegStance,
    /// End the form higher than the ankles: at mid-thigh, each leg closed by a flat cap.
    #[arg(long, value_parser = stop_at_parser())]
    stop_at: Option<StopAt>,
}

impl LegArgs {
    /// The default mannequin's options with these legs.
    fn options(&self) -> MannequinOptions {
        MannequinOptions { legs: self.legs, stop_at: self.stop_at, ..Default::default() }
    }
}

/// `--legs`: the library's [`LegStance`] by name.
fn stance_parser() -> impl TypedValueParser<Value = LegStance> {
    named(LegStance::ALL, LegStance::name, |s| match s {
        LegStance::Straight => {
            "Parallel and vertical, as a dress form's legs hang; the inseam kept"
        }
        LegStance::AsScanned => "As the customer stood, made symmetric",
    })
}

/// `--stop-at`: the library's [`StopAt`] by name.
fn stop_at_parser() -> impl TypedValueParser<Value = StopAt> {
    named(StopAt::ALL, StopAt::name, |s| match s {
        StopAt::Thigh => "Mid-thigh, halfway from the crotch to the knee",
    })
}

/// How a command writes its output mesh (see [`Export`]).
#[derive(Debug, Clone, clap::Args)]
pub struct ExportArgs {
    /// The mesh's file format (glb: binary glTF, metres, Y up).
    #[arg(long, value_enum, default_value_t = MeshFormat::Obj)]
    format: MeshFormat,
    /// The mesh's length unit [default: mm; m for glb].
    #[arg(long, value_enum, conflicts_with = "scan_frame")]
    units: Option<MeshUnits>,
    /// The mesh's up axis [default: z, the canonical frame; y for glb].
    #[arg(long, value_enum, conflicts_with = "scan_frame")]
    up: Option<MeshUp>,
    /// Write the mesh in the scan's own units and axes (default: the canonical frame).
    #[arg(long)]
    scan_frame: bool,
}

/// `--format`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
enum MeshFormat {
    Obj,
    Ply,
    Stl,
    Glb,
}

/// `--units` of an output mesh.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
enum MeshUnits {
    Mm,
    Cm,
    M,
}

/// `--up` of an output mesh.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
enum MeshUp {
    Z,
    Y,
}

impl ExportArgs {
    /// The export of a mesh of `scan` (checked: glb is metres and Y up).
    fn export(&self, scan: &Scan) -> Result<Export, Failure> {
        let format = match self.format {
            MeshFormat::Obj => Format::Obj,
            MeshFormat::Ply => Format::Ply,
            MeshFormat::Stl => Format::Stl,
            MeshFormat::Glb => Format::Glb,
        };
        let usual = Export::canonical(format).placement;
        let placement = match (&usual, self.scan_frame) {
            (_, true) => Placement::AsIs {
                units: scan.frame.units,
                frame: format!(
                    "the scan's own ({}, up {})",
                    messages::path(&scan.source),
                    scan.frame.up
                ),
            },
            (Placement::Canonical { units, up }, false) => Placement::Canonical {
                units: self.units.map_or(*units, |u| match u {
                    MeshUnits::Mm => Units::Mm,
                    MeshUnits::Cm => Units::Cm,
                    MeshUnits::M => Units::M,
                }),
                up: self.up.map_or(*up, |u| match u {
                    MeshUp::Z => UpAxis::Z,
                    MeshUp::Y => UpAxis::Y,
                }),
            },
            (placement, false) => placement.clone(),
        };
        Export::new(format, placement).map_err(Failure::bad_input)
    }
}

/// `--report PATH`: the customer report (`report.html`) of a command's output set, also
/// written to a file of the user's choice.
#[derive(Debug, Clone, Default, clap::Args)]
pub struct ReportArgs {
    /// Also write the customer report (report.html) to this file.
    #[arg(long, value_name = "PATH")]
    report: Option<PathBuf>,
}

impl ReportArgs {
    /// Commits `set` into `out`, then writes its report to `--report`'s file, if one is
    /// given, atomically.
    fn commit(&self, set: OutputSet, out: &Path) -> Result<(), Failure> {
        let copy = self.report.as_deref().zip(set.get(REPORT).map(<[u8]>::to_vec));
        set.commit(out).map_err(Failure::other)?;
        match copy {
            Some((path, html)) => write_atomically(path, &html).map_err(Failure::other),
            None => Ok(()),
        }
    }
}

/// A command that failed: the message to print and the process exit code.
#[derive(Debug)]
pub struct Failure {
    pub message: String,
    pub exit_code: u8,
}

impl Failure {
    /// Input the user gave is unusable: exit status 2.
    fn bad_input(e: impl std::fmt::Display) -> Self {
        Failure { message: e.to_string(), exit_code: 2 }
    }

    /// Anything else (an output that cannot be written, ...): exit status 1.
    fn other(e: impl std::fmt::Display) -> Self {
        Failure { message: e.to_string(), exit_code: 1 }
    }
}

/// `value`, the number given for `option`, if it is finite and in `range`; else a one-line
/// error (exit status 2) naming the option, the value and the range in `unit` (`" mm"`, or
/// empty): `--slower: 1e308 is not in [1, 65535]`.
fn within(
    option: &str,
    value: f64,
    range: impl RangeBounds<f64>,
    unit: &str,
) -> Result<f64, Failure> {
    if value.is_finite() && range.contains(&value) {
        return Ok(value);
    }
    let end = |bound: Bound<&f64>, unbounded: &str| match bound {
        Bound::Included(x) | Bound::Excluded(x) => messages::number(*x).to_string(),
        Bound::Unbounded => unbounded.to_string(),
    };
    let open = if matches!(range.start_bound(), Bound::Included(_)) { "[" } else { "(" };
    let close = if matches!(range.end_bound(), Bound::Included(_)) { "]" } else { ")" };
    let (low, high) = (end(range.start_bound(), "-inf"), end(range.end_bound(), "inf"));
    Err(Failure::bad_input(format!(
        "{option}: {} is not in {open}{low}, {high}{close}{unit}",
        messages::number(value)
    )))
}

/// Runs the command `args` names.
pub fn run(args: Args) -> Result<(), Failure> {
    match args.command {
        Command::Info(a) => info::run(&a),
        Command::Slice(a) => slice::run(&a),
        Command::Measure(a) => measure::run(&a),
        Command::Symmetrize(a) => symmetrize::run(&a),
        Command::Reconstruct(a) => reconstruct::run(&a),
        Command::Setpoints(a) => setpoints::run(&a),
        Command::Run(a) => run::run(&a),
        Command::Sim(a) => sim::run(&a),
        Command::Demo(a) => demo::run(&a),
        Command::Drive(a) => drive::run(&a),
        Command::FitTest(a) => fit_test::run(&a),
        Command::Status(a) => status::run(&a),
        Command::Estop(a) => estop::run(&a),
        Command::Model(a) => model::run(&a),
        Command::Reset(a) => reset::run(&a),
        Command::Form(a) => form::run(&a),
        Command::Batch(a) => batch::run(&a),
        Command::BatchMerge(a) => batch::merge(&a),
        Command::Watch(a) => watch::run(&a),
    }
}

/// Set once writing to standard output failed (other than by a closed pipe).
static OUTPUT_FAILED: AtomicBool = AtomicBool::new(false);

/// Writes command output. A reader that closed the pipe (`dressform slice ... | head`)
/// just ends the output; any other failure (a full disk) is reported once and fails the
/// command (see [`output_failed`]), without stopping what it is doing (a form mid-move).
pub fn write_out(text: std::fmt::Arguments) {
    if let Err(e) = std::io::stdout().lock().write_fmt(text)
        && e.kind() != ErrorKind::BrokenPipe
        && !OUTPUT_FAILED.swap(true, Ordering::Relaxed)
    {
        errln!("error: cannot write the output: {e}");
    }
}

/// Writes a message on standard error; one that standard error cannot take (closed, full) is
/// lost rather than a reason to stop.
pub fn write_err(text: std::fmt::Arguments) {
    let _ = std::io::stderr().lock().write_fmt(text);
}

/// Whether some output could not be written.
pub fn output_failed() -> bool {
    OUTPUT_FAILED.load(Ordering::Relaxed)
}

/// The files `paths` name: files as given, and in each folder among them its files that are
/// `wanted` (sorted by name); a folder with none is an error naming `what` it lacks.
fn files_in(
    paths: &[PathBuf],
    wanted: impl Fn(&Path) -> bool,
    what: &str,
) -> Result<Vec<PathBuf>, Failure> {
    let mut files = Vec::new();
    for path in paths {
        if !path.is_dir() {
            files.push(path.clone());
            continue;
        }
        let read = std::fs::read_dir(path)
            .map_err(|e| Failure::bad_input(format!("{}: cannot read: {e}", path.display())))?;
        let mut found: Vec<PathBuf> =
            read.filter_map(|e| e.ok().map(|e| e.path())).filter(|p| wanted(p)).collect();
        if found.is_empty() {
            return Err(Failure::bad_input(format!(
                "{}: no {what} in this directory",
                path.display()
            )));
        }
        found.sort();
        files.extend(found);
    }
    Ok(files)
}

/// Prints a warning about `file` on standard error (bounded: see [`messages::bounded`]).
fn warn(file: &str, message: &str) {
    errln!("warning: {}", messages::bounded(&format!("{file}: {message}")));
}

/// Prints `warnings` about `file` (a prepared scan's: see [`dressform::body::scan::prepare`]),
/// in their order; through `bar`, when one is showing, so that they do not tear it.
fn print_warnings(file: &str, warnings: &[String], bar: Option<&indicatif::ProgressBar>) {
    for w in warnings {
        match bar {
            Some(bar) => bar.suspend(|| warn(file, w)),
            None => warn(file, w),
        }
    }
}

/// A progress bar on standard error for `steps` steps; hidden in `--json` mode and when
/// standard error is not a terminal.
fn progress_bar(json: bool, steps: u64) -> indicatif::ProgressBar {
    if json {
        return indicatif::ProgressBar::hidden();
    }
    let bar = indicatif::ProgressBar::new(steps);
    if let Ok(style) = indicatif::ProgressStyle::with_template("{spinner} [{bar:24}] {msg}") {
        bar.set_style(style.progress_chars("=> "));
    }
    bar.enable_steady_tick(std::time::Duration::from_millis(100));
    bar
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_out_of_range_name_the_option_and_the_range() {
        let message = |r: Result<f64, Failure>| r.unwrap_err().message;
        assert_eq!(
            message(within("--slower", 1e308, 1.0..=65535.0, "")),
            "--slower: 1e308 is not in [1, 65535]"
        );
        let positive = (Bound::Excluded(0.0), Bound::Included(655.34));
        assert_eq!(
            message(within("--tolerance", 0.0, positive, " mm")),
            "--tolerance: 0 is not in (0, 655.34] mm"
        );
        assert_eq!(
            message(within("--girth-tolerance", f64::INFINITY, 0.0.., " mm")),
            "--girth-tolerance: inf is not in [0, inf) mm"
        );
        assert_eq!(within("--beta", -5.0, -5.0..=5.0, "").unwrap(), -5.0);
        assert_eq!(within("--x", f64::NAN, .., "").unwrap_err().exit_code, 2);
    }
}
