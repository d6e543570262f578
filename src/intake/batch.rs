//! `batch`: every scan of a list processed ([`Processor::process`]), `jobs` at a time, one
//! failing scan never stopping the others; with a shard, only the scans it takes
//! ([`Shard::takes`]). The summary goes to `OUT/summary.csv`, or for a shard to
//! `OUT/summary-shard-K-of-N.csv` (shards may share OUT), which [`super::summary::merge`]
//! joins.

use super::jobs::ScanJob;
use super::process::{Outcome, Processor};
use super::shard::Shard;
use super::summary::{self, Row};
use std::path::{Path, PathBuf};
use std::time::Instant;

/// The summary file of `shard` (or of the whole batch) in `out`.
pub fn summary_path(out: &Path, shard: Option<Shard>) -> PathBuf {
    match shard {
        None => out.join(summary::FILE),
        Some(s) => {
            let text = s.to_string();
            let (k, n) = text.split_once('/').unwrap_or((&text, ""));
            out.join(format!("{SHARD_PREFIX}{k}-of-{n}.csv"))
        }
    }
}

/// How a shard's summary file name starts (`summary-shard-2-of-8.csv`).
pub const SHARD_PREFIX: &str = "summary-shard-";

/// Processes the scans of `scans` that `shard` takes (all without one) into `out`, `jobs`
/// at a time, calling `progress` as each ends; writes the summary and returns its rows.
/// Only the summary's failing to be written is an error: a scan that fails is a row.
pub fn run(
    processor: &Processor,
    scans: &[ScanJob],
    out: &Path,
    jobs: usize,
    shard: Option<Shard>,
    progress: impl Fn(&ScanJob, &Row, &Result<Outcome, String>) + Sync,
) -> Result<Vec<Row>, String> {
    let mine: Vec<&ScanJob> =
        scans.iter().filter(|j| shard.is_none_or(|s| s.takes(&j.customer))).collect();
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(jobs)
        .build()
        .map_err(|e| format!("cannot start {jobs} workers: {e}"))?;
    let rows: Vec<Row> = pool.install(|| {
        use rayon::prelude::*;
        mine.par_iter()
            .map(|job| {
                let start = Instant::now();
                let outcome = processor.process_guarded(job, out);
                let row = Row::new(&job.customer, &outcome, start.elapsed().as_secs_f64());
                progress(job, &row, &outcome);
                row
            })
            .collect()
    });
    std::fs::create_dir_all(out).map_err(|e| format!("{}: cannot create: {e}", out.display()))?;
    summary::write(&summary_path(out, shard), &rows)?;
    Ok(rows)
}
