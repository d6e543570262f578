//! The scans of a batch: every scan file of a folder, or the rows of a manifest (CSV with a
//! header: `path,customer` and optionally `units` and `up`, empty for "detect"; a relative
//! path is taken from the manifest's folder). Each scan is one customer, whose id names its
//! output folder.

use crate::body::scan::format::Format;
use crate::body::scan::frame::{Direction, FrameOptions, Units};
use crate::messages;
use std::collections::HashMap;
use std::path::{Path, PathBuf};

/// One scan to process.
#[derive(Debug, Clone)]
pub struct ScanJob {
    /// The scan file.
    pub path: PathBuf,
    /// The customer id: the name of the scan's output folder.
    pub customer: String,
    /// The scan's frame, where it is given.
    pub frame: FrameOptions,
}

/// Checks that `id` can name an output folder: not empty, no path separator, not hidden or
/// `..`, no control characters.
pub fn check_customer(id: &str) -> Result<(), String> {
    let problem = if id.is_empty() {
        "is empty"
    } else if id.contains(['/', '\\']) {
        "contains a path separator"
    } else if id.starts_with('.') {
        "starts with a dot"
    } else if id.chars().any(char::is_control) {
        "contains control characters"
    } else {
        return Ok(());
    };
    Err(format!("customer id '{}' {problem}", messages::bounded(&id.escape_default().to_string())))
}

/// The customer of the scan at `path` (a folder's scan): its file stem.
pub fn customer_of(path: &Path) -> Result<String, String> {
    let stem = path
        .file_stem()
        .and_then(|s| s.to_str())
        .ok_or_else(|| format!("{}: the file name is not UTF-8 text", messages::path(path)))?;
    check_customer(stem).map_err(|e| format!("{}: {e}", messages::path(path)))?;
    Ok(stem.to_string())
}

/// Whether `path` names a scan file: a format dressform reads, not hidden.
pub fn is_scan(path: &Path) -> bool {
    let hidden = path.file_name().and_then(|n| n.to_str()).is_none_or(|n| n.starts_with('.'));
    !hidden && Format::from_path(path).is_some()
}

/// The scans of `dir` (not its sub-folders), by name, each in the frame `frame` gives.
pub fn from_dir(dir: &Path, frame: FrameOptions) -> Result<Vec<ScanJob>, String> {
    let read =
        std::fs::read_dir(dir).map_err(|e| format!("{}: cannot read: {e}", messages::path(dir)))?;
    let mut paths: Vec<PathBuf> = read
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.is_file() && is_scan(p))
        .collect();
    paths.sort();
    if paths.is_empty() {
        return Err(format!(
            "{}: no .obj, .ply, .stl or .glb file in this folder",
            messages::path(dir)
        ));
    }
    let jobs = paths
        .into_iter()
        .map(|path| Ok(ScanJob { customer: customer_of(&path)?, path, frame }))
        .collect::<Result<Vec<_>, String>>()?;
    unique(jobs, |j| messages::path(&j.path))
}

/// The rows of a manifest (see the module documentation); `frame` for cells left empty.
pub fn from_manifest(manifest: &Path, frame: FrameOptions) -> Result<Vec<ScanJob>, String> {
    let file = messages::path(manifest);
    let mut reader = csv::ReaderBuilder::new()
        .trim(csv::Trim::All)
        .from_path(manifest)
        .map_err(|e| format!("{file}: cannot read: {e}"))?;
    let headers = reader.headers().map_err(|e| format!("{file}: {e}"))?.clone();
    let column = |name: &str| headers.iter().position(|h| h.eq_ignore_ascii_case(name));
    let (Some(path_at), Some(customer_at)) = (column("path"), column("customer")) else {
        return Err(format!(
            "{file}: the header must name the columns path and customer (and may name units, up); it has {}",
            headers.iter().collect::<Vec<_>>().join(",")
        ));
    };
    let (units_at, up_at) = (column("units"), column("up"));
    let base = manifest.parent().unwrap_or(Path::new("."));
    let mut jobs = Vec::new();
    for record in reader.records() {
        let record = record.map_err(|e| format!("{file}: {e}"))?;
        let line = record.position().map_or(0, |p| p.line());
        let at = |what: String| format!("{file} line {line}: {what}");
        let cell = |i: Option<usize>| i.and_then(|i| record.get(i)).unwrap_or("");
        let path = cell(Some(path_at));
        if path.is_empty() {
            return Err(at("the path is empty".into()));
        }
        let customer = cell(Some(customer_at)).to_string();
        check_customer(&customer).map_err(at)?;
        let units = match cell(units_at) {
            "" => frame.units,
            u => Some(Units::ALL.into_iter().find(|x| x.symbol() == u).ok_or_else(|| {
                at(format!("units '{}' is not one of m, dm, cm, mm, in", messages::bounded(u)))
            })?),
        };
        let up = match cell(up_at) {
            "" => frame.up,
            u => Some(u.parse::<Direction>().map_err(|e| at(format!("up: {e}")))?),
        };
        let path = base.join(path);
        jobs.push(ScanJob { path, customer, frame: FrameOptions { units, up, ..frame } });
    }
    if jobs.is_empty() {
        return Err(format!("{file}: no scans listed"));
    }
    unique(jobs, |j| format!("{} (customer {})", messages::path(&j.path), j.customer))
}

/// `jobs` if no two share a customer id (they would share an output folder).
fn unique(jobs: Vec<ScanJob>, name: impl Fn(&ScanJob) -> String) -> Result<Vec<ScanJob>, String> {
    let mut seen: HashMap<&str, &ScanJob> = HashMap::new();
    for job in &jobs {
        if let Some(first) = seen.insert(&job.customer, job) {
            return Err(format!(
                "{} and {} are both customer '{}': one output folder each is needed",
                name(first),
                name(job),
                job.customer
            ));
        }
    }
    drop(seen);
    Ok(jobs)
}
