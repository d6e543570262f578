//! `dressform batch <DIR | manifest.csv> -o <OUT> [--jobs N] [--shard K/N | --shard-count N]`
//! and `dressform batch-merge <summary.csv | OUT>... -o <merged.csv>`: every scan of a folder
//! or manifest into `OUT/<customer>/` (see [`dressform::intake`]), and shards' summaries
//! joined. The processing options are shared with `watch` ([`IntakeArgs`]).

use super::link::FormArg;
use super::{Failure, FrameArgs, LegArgs, SmoothArgs, warn};
use dressform::intake::batch::{self, SHARD_PREFIX};
use dressform::intake::jobs::{self, ScanJob};
use dressform::intake::process::{Outcome, Processor};
use dressform::intake::shard::Shard;
use dressform::intake::summary::{self, HEIGHT, Row, Status};
use dressform::run::reconstruct::ReconstructOptions;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};

/// How each scan is processed: `batch` and `watch` alike.
#[derive(Debug, clap::Args)]
pub struct IntakeArgs {
    /// The body model (.glb) [default: the built-in model].
    #[arg(long)]
    model: Option<PathBuf>,
    /// Joint angles to set on every symmetric pose (TOML; see docs/formats.md).
    #[arg(long)]
    pose: Option<PathBuf>,
    #[command(flatten)]
    form: FormArg,
    #[command(flatten)]
    frame: FrameArgs,
    #[command(flatten)]
    smooth: SmoothArgs,
    #[command(flatten)]
    legs: LegArgs,
}

impl IntakeArgs {
    /// The processor these options describe (the model and form loaded).
    pub fn processor(&self) -> Result<Processor, Failure> {
        let model = super::model::load(self.model.as_deref())?;
        let pose = super::reconstruct::pose_overrides(self.pose.as_deref(), &model)?;
        Ok(Processor {
            model,
            options: ReconstructOptions {
                pose,
                mannequin: self.legs.options(),
                ..Default::default()
            },
            form: self.form.load()?,
            smooth: self.smooth.smooth,
        })
    }

    /// The frame given for every scan.
    pub fn frame(&self) -> dressform::body::scan::frame::FrameOptions {
        self.frame.options()
    }
}

#[derive(Debug, clap::Args)]
pub struct BatchArgs {
    /// A folder of scans (.obj, .ply, .stl, .glb; each scan's customer id is its file stem),
    /// or a manifest (.csv with the columns path, customer and, optionally, units and up).
    scans: PathBuf,
    /// The output folder: OUT/<customer>/ per scan, and the summary.
    #[arg(short, long)]
    out: PathBuf,
    /// Scans processed at a time (each one uses every core already).
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u16).range(1..=256))]
    jobs: u16,
    /// Process only shard K of N (K from 1): the scans whose customer id hashes to it
    /// (FNV-1a mod N). Without it, $SLURM_ARRAY_TASK_ID or $JOB_COMPLETION_INDEX choose it.
    #[arg(long, value_name = "K/N", value_parser = Shard::parse)]
    shard: Option<Shard>,
    /// The number of shards N, with $JOB_COMPLETION_INDEX (a Kubernetes Indexed Job's
    /// completions); checked against $SLURM_ARRAY_TASK_COUNT.
    #[arg(long, value_name = "N", conflicts_with = "shard",
          value_parser = clap::value_parser!(u64).range(1..))]
    shard_count: Option<u64>,
    #[command(flatten)]
    intake: IntakeArgs,
}

pub fn run(args: &BatchArgs) -> Result<(), Failure> {
    let shard = match args.shard {
        Some(shard) => Some(shard),
        None => Shard::from_env(|name| std::env::var(name).ok(), args.shard_count)
            .map_err(Failure::bad_input)?,
    };
    if shard.is_none() && args.shard_count.is_some() {
        return Err(Failure::bad_input(
            "--shard-count goes with $JOB_COMPLETION_INDEX or $SLURM_ARRAY_TASK_ID, and neither is set",
        ));
    }
    let scans = scan_list(&args.scans, &args.intake)?;
    let processor = args.intake.processor()?;
    let total = scans.iter().filter(|j| shard.is_none_or(|s| s.takes(&j.customer))).count();
    match shard {
        Some(s) => errln!("shard {s}: {total} of {} scans", scans.len()),
        None => errln!("{total} scans"),
    }
    let count = AtomicUsize::new(0);
    let progress = |job: &ScanJob, row: &Row, outcome: &Result<Outcome, String>| {
        let k = count.fetch_add(1, Ordering::Relaxed) + 1;
        if let Ok(Outcome::Done(_, warnings)) = outcome {
            for w in warnings {
                warn(&job.path.display().to_string(), w);
            }
        }
        errln!("[{k}/{total}] {}", progress_line(row));
    };
    let rows = batch::run(&processor, &scans, &args.out, args.jobs.into(), shard, progress)
        .map_err(Failure::other)?;
    let failed = rows.iter().filter(|r| r.status == Status::Failed).count();
    let summary = batch::summary_path(&args.out, shard);
    outln!(
        "{} scans: {} done, {} skipped (done before), {failed} failed; summary in {}",
        rows.len(),
        rows.iter().filter(|r| r.status == Status::Done).count(),
        rows.iter().filter(|r| r.status == Status::Skipped).count(),
        summary.display()
    );
    match failed {
        0 => Ok(()),
        n => Err(Failure::bad_input(format!(
            "{n} of {} scans could not be processed (the error column of {} says why)",
            rows.len(),
            summary.display()
        ))),
    }
}

/// One scan's progress line: its customer, status, time, the customer's height and the
/// mannequin's girths, or its error.
pub fn progress_line(row: &Row) -> String {
    let mm =
        |k: &str| row.measures.get(k).copied().flatten().map_or("-".into(), |v| format!("{v:.0}"));
    match row.status {
        Status::Failed => format!("{}: failed: {}", row.customer, row.error),
        status => format!(
            "{}: {} in {:.1} s: height {} mm, chest {}, waist {}, hip {}",
            row.customer,
            status.name(),
            row.seconds,
            mm(HEIGHT),
            mm("chest_mm"),
            mm("waist_mm"),
            mm("hip_mm")
        ),
    }
}

/// The scans `path` names: a folder's, or a manifest's rows.
fn scan_list(path: &Path, intake: &IntakeArgs) -> Result<Vec<ScanJob>, Failure> {
    let list = if path.is_dir() {
        jobs::from_dir(path, intake.frame())
    } else {
        jobs::from_manifest(path, intake.frame())
    };
    list.map_err(Failure::bad_input)
}

#[derive(Debug, clap::Args)]
pub struct MergeArgs {
    /// Shards' summaries: files, or output folders (their summary-shard-*.csv).
    #[arg(required = true)]
    summaries: Vec<PathBuf>,
    /// The merged summary to write.
    #[arg(short, long)]
    out: PathBuf,
}

pub fn merge(args: &MergeArgs) -> Result<(), Failure> {
    let shard = |p: &Path| {
        let name = p.file_name().and_then(|n| n.to_str()).unwrap_or("");
        name.starts_with(SHARD_PREFIX) && name.ends_with(".csv")
    };
    let files = super::files_in(&args.summaries, shard, &format!("{SHARD_PREFIX}*.csv"))?;
    let inputs: Vec<&Path> = files.iter().map(PathBuf::as_path).collect();
    let rows = summary::merge(&inputs, &args.out).map_err(Failure::bad_input)?;
    outln!("{rows} scans from {} summaries in {}", inputs.len(), args.out.display());
    Ok(())
}
