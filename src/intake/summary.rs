//! `summary.csv`: one row per scan of a batch (or shard), sorted by customer id: `customer`,
//! `status` (`done`, `skipped`: its outputs were there from the same input, `failed`),
//! the customer's `height_mm`, the mannequin's `chest_mm`, `waist_mm`, `hip_mm` (what the
//! form is shaped to), every ISO 8559-1 dimension of the pose-symmetric scan (left and right of the
//! bilateral ones in two columns; empty where not measured), `seconds` (wall time) and
//! `error` (one line, for `failed`). Written atomically; [`merge`] joins shards' summaries.

use crate::atomic_output::write_atomically;
use crate::messages;
use crate::run::report::definitions::DEFINITIONS;
use std::collections::BTreeMap;
use std::path::Path;

/// The summary's file name.
pub const FILE: &str = "summary.csv";
/// The customer's height column.
pub const HEIGHT: &str = "height_mm";
/// The sides of a bilateral dimension, each a column (`thigh_girth_mm_left`).
pub const SIDES: [&str; 2] = ["left", "right"];
/// The ISO 8559-1 dimensions measured on each side of the body
/// ([`crate::shape::measure::Bilateral`] fields of `BodyDimensions`).
const BILATERAL: [&str; 8] = [
    "shoulder_slope_deg",
    "thigh_girth_mm",
    "knee_girth_mm",
    "calf_girth_mm",
    "ankle_girth_mm",
    "upper_arm_girth_mm",
    "wrist_girth_mm",
    "arm_length_mm",
];

/// The status of a scan in the summary.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Status {
    /// Processed by this run.
    Done,
    /// Its outputs were already there, made from the same input.
    Skipped,
    /// It could not be processed.
    Failed,
}

impl Status {
    /// As the summary spells it.
    pub fn name(self) -> &'static str {
        match self {
            Status::Done => "done",
            Status::Skipped => "skipped",
            Status::Failed => "failed",
        }
    }
}

/// One scan's row.
#[derive(Debug, Clone)]
pub struct Row {
    /// The customer id.
    pub customer: String,
    /// What became of the scan.
    pub status: Status,
    /// The measurements by column (empty for a failed scan).
    pub measures: BTreeMap<String, Option<f64>>,
    /// Wall time (s).
    pub seconds: f64,
    /// The one-line error of a failed scan.
    pub error: String,
}

/// The summary's columns, in order.
pub fn columns() -> Vec<String> {
    let mut c: Vec<String> =
        ["customer", "status", HEIGHT, "chest_mm", "waist_mm", "hip_mm"].map(String::from).to_vec();
    for d in DEFINITIONS {
        if BILATERAL.contains(&d.key) {
            c.extend(SIDES.map(|side| format!("{}_{side}", d.key)));
        } else {
            c.push(d.key.to_string());
        }
    }
    c.extend(["seconds", "error"].map(String::from));
    c
}

/// Writes `rows` (sorted by customer) as `path`, atomically.
pub fn write(path: &Path, rows: &[Row]) -> Result<(), String> {
    let columns = columns();
    let mut rows: Vec<&Row> = rows.iter().collect();
    rows.sort_by(|a, b| a.customer.cmp(&b.customer));
    let records = rows.iter().map(|row| {
        columns
            .iter()
            .map(|c| match c.as_str() {
                "customer" => row.customer.clone(),
                "status" => row.status.name().to_string(),
                "seconds" => format!("{:.1}", row.seconds),
                "error" => row.error.clone(),
                measure => row
                    .measures
                    .get(measure)
                    .copied()
                    .flatten()
                    .map_or_else(String::new, |v| format!("{v:.1}")),
            })
            .collect::<Vec<String>>()
    });
    write_csv(path, &columns, records)
}

/// Writes `header` and `records` as the CSV file `path`, atomically.
fn write_csv(
    path: &Path,
    header: &[String],
    records: impl Iterator<Item = Vec<String>>,
) -> Result<(), String> {
    let mut w = csv::Writer::from_writer(Vec::new());
    let fail = |e: csv::Error| format!("{}: {e}", messages::path(path));
    w.write_record(header).map_err(fail)?;
    for r in records {
        w.write_record(&r).map_err(fail)?;
    }
    let bytes = w.into_inner().map_err(|e| format!("{}: {e}", messages::path(path)))?;
    write_atomically(path, &bytes).map_err(|e| e.to_string())
}

/// Joins the summaries `inputs` into `output` (atomically), rows sorted by customer;
/// returns the number of rows. Summaries with other columns than the first's, and a customer
/// in two of them, are refused (one line naming the files).
pub fn merge(inputs: &[&Path], output: &Path) -> Result<usize, String> {
    let mut header: Option<(csv::StringRecord, &Path)> = None;
    let mut rows: BTreeMap<String, (Vec<String>, &Path)> = BTreeMap::new();
    for &input in inputs {
        let file = messages::path(input);
        let mut reader =
            csv::Reader::from_path(input).map_err(|e| format!("{file}: cannot read: {e}"))?;
        let columns = reader.headers().map_err(|e| format!("{file}: {e}"))?.clone();
        match &header {
            None => header = Some((columns, input)),
            Some((first, from)) if *first != columns => {
                let differs = first.iter().zip(columns.iter()).position(|(a, b)| a != b);
                let what = match differs {
                    Some(i) => format!(
                        "column {} is '{}' there and '{}' here",
                        i + 1,
                        &first[i],
                        &columns[i]
                    ),
                    None => format!("{} columns there and {} here", first.len(), columns.len()),
                };
                return Err(format!(
                    "{file}: its columns differ from {}'s ({what}): summaries of different versions cannot be merged",
                    messages::path(from)
                ));
            }
            Some(_) => {}
        }
        for record in reader.records() {
            let record = record.map_err(|e| format!("{file}: {e}"))?;
            let customer = record.get(0).unwrap_or_default().to_string();
            let values = record.iter().map(String::from).collect();
            if let Some((_, other)) = rows.insert(customer.clone(), (values, input)) {
                return Err(format!(
                    "customer '{}' is in {} and in {file}: were shards run with different --shard counts?",
                    messages::bounded(&customer),
                    messages::path(other)
                ));
            }
        }
    }
    let Some((header, _)) = header else { return Err("no summaries to merge".into()) };
    let header: Vec<String> = header.iter().map(String::from).collect();
    let n = rows.len();
    write_csv(output, &header, rows.into_values().map(|(v, _)| v))?;
    Ok(n)
}
