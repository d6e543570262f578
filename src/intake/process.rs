//! The one way a scan is processed unattended, shared by `batch` and `watch`: the scan
//! (and its landmark file) read and hashed; skipped when its output folder already holds
//! the outputs of the same input; else pose symmetry, the mannequin and the form's
//! set-points (as `dressform run` makes them, without driving), committed into
//! `OUT/<customer>/` as one set ([`crate::atomic_output::OutputSet::commit`]) with `intake.json`, the record of
//! what was made from which input.

use super::hash::Fnv1a;
use super::jobs::ScanJob;
use super::landmarks::{self, LandmarksFile};
use super::summary::{Row, Status};
use crate::body::mesh::decimate::WORKING_TRIANGLES;
use crate::body::scan::format::{Export, Format};
use crate::body::scan::frame::Units;
use crate::body::scan::{self, PreparedScan};
use crate::messages;
use crate::pose::body_model::BodyModel;
use crate::run::outputs::Outputs;
use crate::run::reconstruct::{ReconstructOptions, Reshaped, reconstruct_shape};
use crate::shape::measure::measure_scan;
use form_description::FormDescription;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// The record of a processed scan, in its output folder.
pub const RECORD: &str = "intake.json";
/// The landmarks of a scan that came with a landmark file, in its output folder.
pub const LANDMARKS: &str = "landmarks.json";
/// [`Record::format`].
const RECORD_FORMAT: &str = "dressform-intake/1";

/// How every scan is processed.
#[derive(Debug, Clone)]
pub struct Processor {
    /// The body model fitted to each scan.
    pub model: BodyModel,
    /// The fit's, the symmetric pose's and the mannequin's options.
    pub options: ReconstructOptions,
    /// The form whose set-points are computed.
    pub form: FormDescription,
    /// Taubin smoothing passes before the fit.
    pub smooth: usize,
}

/// What `intake.json` records: the input (its hash covers the scan's bytes, the frame it was
/// given and the landmark file's bytes) and the measurements of the summary.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Record {
    /// `dressform-intake/1`.
    pub format: String,
    /// The customer id.
    pub customer: String,
    /// The scan's file name.
    pub scan: String,
    /// The input's hash ([`input_hash`]).
    pub input_hash: String,
    /// The scan's units.
    pub units: Units,
    /// Whether they were detected.
    pub units_detected: bool,
    /// Landmarks read from the landmark file (0 without one).
    pub landmarks: usize,
    /// The summary's measurements by column ([`super::summary`]): `None` where not measured.
    pub measures: BTreeMap<String, Option<f64>>,
}

/// What became of a scan.
#[derive(Debug, Clone)]
pub enum Outcome {
    /// Processed now; the scan's warnings.
    Done(Record, Vec<String>),
    /// Its outputs were already there, made from the same input.
    Skipped(Record),
}

impl Outcome {
    /// The record.
    pub fn record(&self) -> &Record {
        match self {
            Outcome::Done(r, _) | Outcome::Skipped(r) => r,
        }
    }
}

/// The hash of a scan's input, as [`Record::input_hash`] states it (`fnv1a64:` and 16 hex
/// digits): FNV-1a over the scan's bytes, the frame given for it and the landmark file's
/// bytes, if any.
pub fn input_hash(scan: &[u8], job: &ScanJob, landmark_file: Option<&[u8]>) -> String {
    let mut h = Fnv1a::default();
    h.update(scan);
    let f = &job.frame;
    let frame = format!("\0units={:?};up={:?};facing={:?}", f.units, f.up, f.facing);
    h.update(frame.as_bytes());
    if let Some(bytes) = landmark_file {
        h.update(b"\0landmarks\0");
        h.update(bytes);
    }
    format!("fnv1a64:{:016x}", h.finish())
}

/// The record in `dir`, if it holds one.
pub fn record_in(dir: &Path) -> Option<Record> {
    let bytes = std::fs::read(dir.join(RECORD)).ok()?;
    serde_json::from_slice(&bytes).ok()
}

/// Reads a file, the error one line naming it.
fn read(path: &Path) -> Result<Vec<u8>, String> {
    std::fs::read(path).map_err(|e| format!("{}: cannot read: {e}", messages::path(path)))
}

impl Processor {
    /// The output folder of `job` in `out`.
    pub fn folder(out: &Path, job: &ScanJob) -> PathBuf {
        out.join(&job.customer)
    }

    /// The input hash of `job` as it is on disk now.
    pub fn hash_of(job: &ScanJob) -> Result<String, String> {
        let landmark_file = landmarks::beside(&job.path).map(|p| read(&p)).transpose()?;
        Ok(input_hash(&read(&job.path)?, job, landmark_file.as_deref()))
    }

    /// Processes `job` into `out/<customer>/` (see the module documentation). The error is
    /// one line: the file and the problem.
    pub fn process(&self, job: &ScanJob, out: &Path) -> Result<Outcome, String> {
        let bytes = read(&job.path)?;
        let landmark_path = landmarks::beside(&job.path);
        let landmark_file = landmark_path.as_deref().map(read).transpose()?;
        let hash = input_hash(&bytes, job, landmark_file.as_deref());
        let dir = Self::folder(out, job);
        if let Some(record) = record_in(&dir).filter(|r| r.input_hash == hash) {
            return Ok(Outcome::Skipped(record));
        }
        let landmarks = match (&landmark_path, &landmark_file) {
            (Some(path), Some(text)) => {
                let text = String::from_utf8_lossy(text);
                landmarks::parse(&text, path)?
            }
            _ => Vec::new(),
        };
        let scan = scan::from_bytes(&bytes, &job.path, &job.frame).map_err(|e| e.to_string())?;
        let PreparedScan { scan, warnings, .. } =
            PreparedScan::reduced(scan, self.smooth, Some(WORKING_TRIANGLES));
        let done = reconstruct_shape(&scan, &self.model, &self.options, &self.form, |_| {})
            .map_err(|e| scan.failed(e))?;
        let record = Record {
            format: RECORD_FORMAT.to_string(),
            customer: job.customer.clone(),
            scan: job
                .path
                .file_name()
                .map_or_else(String::new, |n| n.to_string_lossy().into_owned()),
            input_hash: hash,
            units: scan.frame.units,
            units_detected: scan.frame.units_detected,
            landmarks: landmarks.len(),
            measures: measures(&done),
        };
        let shaped = &done.shaped;
        let export = Export::canonical(Format::Obj);
        let mut set =
            Outputs::reposed(&shaped.symmetrized, &done.reposed, &done.as_scanned, &scan, &export)
                .with_form(&self.form, &shaped.fit, &shaped.setpoints)
                .with_customer(&job.customer)
                .files()
                .map_err(|e| format!("{}: {e}", messages::path(&job.path)))?;
        if let Some(path) = &landmark_path {
            let file = LandmarksFile::new(path, &landmarks, &scan.frame);
            set.add(LANDMARKS, pretty(&file, &job.path)?);
        }
        set.add(RECORD, pretty(&record, &job.path)?);
        set.commit(&dir).map_err(|e| e.to_string())?;
        Ok(Outcome::Done(record, warnings))
    }
}

impl Processor {
    /// [`Processor::process`], a panic in the pipeline turned into the scan's error (it
    /// must not take the other scans down).
    pub fn process_guarded(&self, job: &ScanJob, out: &Path) -> Result<Outcome, String> {
        let run = std::panic::AssertUnwindSafe(|| self.process(job, out));
        std::panic::catch_unwind(run).unwrap_or_else(|panic| {
            let what = panic
                .downcast_ref::<String>()
                .map(String::as_str)
                .or_else(|| panic.downcast_ref::<&str>().copied())
                .unwrap_or("no message");
            Err(format!("{}: internal error (please report it): {what}", job.path.display()))
        })
    }
}

/// `value` as pretty JSON; an error names the scan it is of.
fn pretty(value: &impl Serialize, scan: &Path) -> Result<Vec<u8>, String> {
    serde_json::to_vec_pretty(value).map_err(|e| format!("{}: {e}", messages::path(scan)))
}

/// The summary's measurements of a reconstruction (see [`super::summary`]): the customer's
/// height (the pose-symmetric scan's), the mannequin's chest, waist and hip (what the form
/// is shaped to), and every ISO 8559-1 dimension of the pose-symmetric scan (as the customer
/// report gives them; held-back values `None`).
fn measures(done: &Reshaped) -> BTreeMap<String, Option<f64>> {
    let mut m = BTreeMap::new();
    let symmetrized = &done.shaped.symmetrized;
    m.insert(super::summary::HEIGHT.to_string(), Some(symmetrized.comparison.input.height));
    for row in &symmetrized.comparison.table {
        m.insert(format!("{}_mm", row.measure), Some(row.mannequin.tape));
    }
    if let Ok(report) = measure_scan(&done.reposed.posed, &[])
        && let Ok(serde_json::Value::Object(dims)) = serde_json::to_value(&report.dimensions)
    {
        for (key, value) in dims {
            match value {
                serde_json::Value::Object(sides) => {
                    for side in super::summary::SIDES {
                        m.insert(
                            format!("{key}_{side}"),
                            sides.get(side).and_then(serde_json::Value::as_f64),
                        );
                    }
                }
                v => {
                    m.insert(key, v.as_f64());
                }
            }
        }
    }
    m
}

/// A summary row is made from what processing a scan came to, here where that is defined
/// (the summary itself knows nothing of processing).
impl Row {
    /// The row of `customer`'s scan, processed in `seconds` to `outcome` (or an error).
    pub fn new(customer: &str, outcome: &Result<Outcome, String>, seconds: f64) -> Row {
        let (status, measures, error) = match outcome {
            Ok(Outcome::Done(r, _)) => (Status::Done, r.measures.clone(), String::new()),
            Ok(Outcome::Skipped(r)) => (Status::Skipped, r.measures.clone(), String::new()),
            Err(e) => (Status::Failed, BTreeMap::new(), messages::bounded(e)),
        };
        Row { customer: customer.to_string(), status, measures, seconds, error }
    }
}
