//! `watch`: a folder watched for new scans, each processed once ([`Processor::process`])
//! into `OUT/<scan's stem>/` as it lands.
//!
//! - **When a scan counts**: when it was renamed into the folder (a copier that writes
//!   `.name.part` and renames it when done), or when its size and modification time have not
//!   changed for the settle time (a copier writing in place; notify does not say when a
//!   writer is done). A file written and renamed within the debouncer's window ([`DEBOUNCE`])
//!   is reported as created, not renamed, and so counts after the settle time too. Hidden
//!   files and files of other formats are not scans.
//! - **Events or polling**: the folder's events (notify, debounced) wake the watcher and mark
//!   renames; the folder is also listed every [`TICK`] (which is what the settle time is
//!   measured on). On network shares, where no events are delivered, `poll` lists it every
//!   so often instead.
//! - **Restarts**: the journal ([`super::journal`]) makes a restart skip every scan done with
//!   the same content and redo one that was cut short.
//! - **Rejected scans** move to `IN/rejected/` with `<name>.error.txt` beside them: what was
//!   seen, and what to do.
//! - **Stopping**: `stop` is checked between scans; the scan in hand is finished (its outputs
//!   committed as a whole) first.

use super::jobs::{self, ScanJob};
use super::journal::{Event, Journal};
use super::process::{Outcome, Processor};
use crate::atomic_output::write_atomically;
use crate::body::scan::frame::FrameOptions;
use crate::messages;
use notify_debouncer_full::notify::event::{ModifyKind, RenameMode};
use notify_debouncer_full::notify::{EventKind, RecursiveMode};
use notify_debouncer_full::{DebounceEventResult, new_debouncer};
use std::collections::{HashMap, HashSet};
use std::ffi::OsString;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc;
use std::time::{Duration, Instant, SystemTime};

/// The folder, under the watched one, that failed scans move to.
pub const REJECTED: &str = "rejected";
/// How often the folder is listed when events are delivered (and the settle time checked).
pub const TICK: Duration = Duration::from_millis(250);
/// How long notify's debouncer gathers a file's events before passing them on (it pairs the
/// two halves of a rename within it).
const DEBOUNCE: Duration = Duration::from_millis(200);

/// How the folder is watched.
#[derive(Debug, Clone, Copy)]
pub struct WatchOptions {
    /// How long a scan's size and time must stay the same before it counts.
    pub settle: Duration,
    /// List the folder this often instead of waiting for its events (network shares).
    pub poll: Option<Duration>,
    /// The frame of every scan, where it is given.
    pub frame: FrameOptions,
}

/// What became of a scan: `Ok` its outcome, `Err` the error and where the scan went.
pub struct Handled<'a> {
    /// The scan (its path where it was found).
    pub job: &'a ScanJob,
    /// The outcome, or the one-line error and the rejected scan's new path.
    pub result: Result<&'a Outcome, (&'a str, &'a Path)>,
    /// Wall time (s).
    pub seconds: f64,
}

/// A scan file as last listed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct Stamp {
    size: u64,
    modified: Option<SystemTime>,
}

/// Watches `input` until `stop` is set, processing each scan that lands into `out`, calling
/// `handled` after each (and before the next is looked at). Errors: the folders cannot be
/// read or written, the journal cannot be written.
pub fn watch(
    processor: &Processor,
    input: &Path,
    out: &Path,
    options: &WatchOptions,
    stop: &AtomicBool,
    mut handled: impl FnMut(Handled),
) -> Result<(), String> {
    let mut journal = Journal::open(out)?;
    // The names of the files renamed in, as events report them.
    let (tx, rx) = mpsc::channel::<Vec<OsString>>();
    // Kept alive while watching; dropped (stopped) on return.
    let _debouncer = match options.poll {
        Some(_) => None,
        None => {
            let on_events = move |result: DebounceEventResult| {
                // Our own listing opens the folder: accesses are no news.
                let news: Vec<_> = result
                    .unwrap_or_default()
                    .into_iter()
                    .filter(|e| !matches!(e.kind, EventKind::Access(_)))
                    .collect();
                let renamed = news.iter().filter_map(|e| match e.kind {
                    EventKind::Modify(ModifyKind::Name(RenameMode::To | RenameMode::Both)) => {
                        e.paths.last().and_then(|p| p.file_name()).map(OsString::from)
                    }
                    _ => None,
                });
                if !news.is_empty() {
                    let _ = tx.send(renamed.collect());
                }
            };
            let mut debouncer = new_debouncer(DEBOUNCE, None, on_events).map_err(|e| {
                format!("{}: cannot watch: {e} (try --poll)", messages::path(input))
            })?;
            debouncer.watch(input, RecursiveMode::NonRecursive).map_err(|e| {
                format!("{}: cannot watch: {e} (try --poll)", messages::path(input))
            })?;
            Some(debouncer)
        }
    };
    let tick = options.poll.unwrap_or(TICK);
    let mut seen: HashMap<PathBuf, (Stamp, Instant)> = HashMap::new();
    let mut renamed: HashSet<OsString> = HashSet::new();
    let mut finished: HashMap<PathBuf, Stamp> = HashMap::new();
    while !stop.load(Ordering::Relaxed) {
        if let Ok(paths) = rx.recv_timeout(tick) {
            renamed.extend(paths);
            renamed.extend(rx.try_iter().flatten());
        }
        let now = Instant::now();
        let listed = list(input)?;
        seen.retain(|p, _| listed.contains_key(p));
        finished.retain(|p, _| listed.contains_key(p));
        let mut ready: Vec<PathBuf> = Vec::new();
        for (path, stamp) in listed {
            let entry = seen.entry(path.clone()).or_insert((stamp, now));
            if entry.0 != stamp {
                *entry = (stamp, now);
            }
            let settled = now.duration_since(entry.1) >= options.settle;
            let renamed_in = path.file_name().is_some_and(|n| renamed.contains(n));
            if finished.get(&path) != Some(&stamp) && (settled || renamed_in) {
                ready.push(path);
            }
        }
        ready.sort();
        for path in ready {
            if stop.load(Ordering::Relaxed) {
                break;
            }
            if let Some(name) = path.file_name() {
                renamed.remove(name);
            }
            if let Some(stamp) = stamp_of(&path) {
                finished.insert(path.clone(), stamp);
            }
            let job = ScanJob { customer: jobs::customer_of(&path)?, path, frame: options.frame };
            take(processor, &job, input, out, &mut journal, &mut handled)?;
        }
    }
    Ok(())
}

/// The scan files of `dir`, with their stamps.
fn list(dir: &Path) -> Result<HashMap<PathBuf, Stamp>, String> {
    let read =
        std::fs::read_dir(dir).map_err(|e| format!("{}: cannot read: {e}", messages::path(dir)))?;
    Ok(read
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| jobs::is_scan(p))
        .filter_map(|p| stamp_of(&p).map(|s| (p, s)))
        .collect())
}

/// The stamp of the regular file at `path`.
fn stamp_of(path: &Path) -> Option<Stamp> {
    let meta = std::fs::metadata(path).ok().filter(std::fs::Metadata::is_file)?;
    Some(Stamp { size: meta.len(), modified: meta.modified().ok() })
}

/// Processes `job` unless the journal has it done with the same content:
/// `started`, then the outputs, then `done`; or the scan rejected, then `failed`.
fn take(
    processor: &Processor,
    job: &ScanJob,
    input: &Path,
    out: &Path,
    journal: &mut Journal,
    handled: &mut impl FnMut(Handled),
) -> Result<(), String> {
    let name = job.path.file_name().map_or_else(String::new, |n| n.to_string_lossy().into_owned());
    let start = Instant::now();
    let (hash, outcome) = match Processor::hash_of(job) {
        Ok(hash) => {
            // A rejected scan was moved away: one with its name and content back in the
            // folder was put there again, and is tried again.
            if journal.last(&name, &hash) == Some(Event::Done) {
                return Ok(());
            }
            journal.record(Event::Started, &name, &hash, "")?;
            let outcome = processor.process_guarded(job, out);
            (hash, outcome)
        }
        Err(e) => (String::new(), Err(e)),
    };
    let seconds = start.elapsed().as_secs_f64();
    match &outcome {
        Ok(o) => {
            journal.record(Event::Done, &name, &hash, "")?;
            handled(Handled { job, result: Ok(o), seconds });
        }
        Err(error) => {
            let to = reject(input, job, &name, &hash, error)?;
            journal.record(Event::Failed, &name, &hash, error)?;
            handled(Handled { job, result: Err((error, &to)), seconds });
        }
    }
    Ok(())
}

/// Moves the scan of `job` to `input/rejected/` with `<name>.error.txt` beside it; returns
/// its new path.
fn reject(
    input: &Path,
    job: &ScanJob,
    name: &str,
    hash: &str,
    error: &str,
) -> Result<PathBuf, String> {
    let dir = input.join(REJECTED);
    std::fs::create_dir_all(&dir)
        .map_err(|e| format!("{}: cannot create: {e}", messages::path(&dir)))?;
    let size =
        std::fs::metadata(&job.path).map_or_else(|_| "?".to_string(), |m| m.len().to_string());
    let text = format!(
        "dressform watch could not process {name} ({size} bytes, input hash {hash}).\n\n\
         What was seen: {error}\n\n\
         What to do: correct the scan (or its landmark file, {stem}.txt, if the error is \
         there), then copy the scan into {input} again: a changed scan is processed anew. \
         If the error names the units or the up axis, restart watch with --units or --up \
         (or export the scan in millimetres, Z up). The scan is kept here, beside this file.\n",
        stem = job.customer,
        input = input.display(),
    );
    write_atomically(&dir.join(format!("{name}.error.txt")), text.as_bytes())
        .map_err(|e| e.to_string())?;
    let to = dir.join(name);
    std::fs::rename(&job.path, &to).map_err(|e| {
        format!("{}: cannot move to {}: {e}", messages::path(&job.path), messages::path(&dir))
    })?;
    Ok(to)
}
