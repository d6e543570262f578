//! The watch journal, `OUT/journal.jsonl`: one JSON object a line, appended and flushed to
//! disk (fsync) before the step it records goes on: `started`, then `done` or `failed`, each
//! with the scan's file name and input hash. A restart reads it back: a scan whose name and
//! hash have a `done` line is not processed again; one that only `started` was cut short and
//! is processed again (its outputs are all or nothing); a `failed` one was moved out of the
//! folder. A line cut short by a kill does not parse and is ignored (the next run starts a
//! new line after it).

use crate::messages;
use serde::{Deserialize, Serialize};
use std::collections::HashMap;
use std::fs::{File, OpenOptions};
use std::io::Write;
use std::path::{Path, PathBuf};

/// The journal's file name in the output folder.
pub const FILE: &str = "journal.jsonl";

/// What a line records.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Event {
    /// Processing began.
    Started,
    /// The outputs are committed.
    Done,
    /// The scan was rejected (moved to `rejected/`).
    Failed,
}

/// One line.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Entry {
    /// What happened.
    pub event: Event,
    /// The scan's file name.
    pub scan: String,
    /// Its input hash.
    pub hash: String,
    /// Seconds since the Unix epoch.
    pub time: u64,
    /// The one-line error of a failed scan.
    #[serde(default, skip_serializing_if = "String::is_empty")]
    pub error: String,
}

/// The journal, open for appending.
#[derive(Debug)]
pub struct Journal {
    path: PathBuf,
    file: File,
    /// The last event of each (scan, hash).
    last: HashMap<(String, String), Event>,
}

impl Journal {
    /// Opens (or creates) the journal in `dir` and reads what it holds.
    pub fn open(dir: &Path) -> Result<Journal, String> {
        let path = dir.join(FILE);
        let fail = |e: std::io::Error| format!("{}: {e}", messages::path(&path));
        std::fs::create_dir_all(dir)
            .map_err(|e| format!("{}: cannot create: {e}", messages::path(dir)))?;
        let text = match std::fs::read(&path) {
            Ok(bytes) => String::from_utf8_lossy(&bytes).into_owned(),
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => String::new(),
            Err(e) => return Err(fail(e)),
        };
        let mut last = HashMap::new();
        for e in text.lines().filter_map(|line| serde_json::from_str::<Entry>(line).ok()) {
            last.insert((e.scan, e.hash), e.event);
        }
        let mut file = OpenOptions::new().create(true).append(true).open(&path).map_err(fail)?;
        // A line cut short by a kill gets its end, so that the next line stands alone.
        if !text.is_empty() && !text.ends_with('\n') {
            file.write_all(b"\n").map_err(fail)?;
        }
        Ok(Journal { path, file, last })
    }

    /// The last event recorded for `scan` with input `hash`.
    pub fn last(&self, scan: &str, hash: &str) -> Option<Event> {
        self.last.get(&(scan.to_string(), hash.to_string())).copied()
    }

    /// Appends `event` for `scan` with input `hash` (and `error`), flushed to disk.
    pub fn record(
        &mut self,
        event: Event,
        scan: &str,
        hash: &str,
        error: &str,
    ) -> Result<(), String> {
        let time = std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map_or(0, |d| d.as_secs());
        let entry =
            Entry { event, scan: scan.into(), hash: hash.into(), time, error: error.into() };
        let mut line = serde_json::to_string(&entry).map_err(|e| e.to_string())?;
        line.push('\n');
        let fail = |e: std::io::Error| format!("{}: {e}", messages::path(&self.path));
        self.file.write_all(line.as_bytes()).map_err(fail)?;
        self.file.sync_data().map_err(fail)?;
        self.last.insert((entry.scan, entry.hash), event);
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_restart_reads_what_was_recorded_and_survives_a_torn_line() {
        let dir = tempfile::tempdir().unwrap();
        let mut j = Journal::open(dir.path()).unwrap();
        j.record(Event::Started, "a.ply", "h1", "").unwrap();
        j.record(Event::Done, "a.ply", "h1", "").unwrap();
        j.record(Event::Started, "b.ply", "h2", "").unwrap();
        drop(j);
        // A kill in the middle of a line.
        let path = dir.path().join(FILE);
        let mut f = OpenOptions::new().append(true).open(&path).unwrap();
        f.write_all(b"{\"event\":\"do").unwrap();
        let mut j = Journal::open(dir.path()).unwrap();
        assert_eq!(j.last("a.ply", "h1"), Some(Event::Done));
        assert_eq!(j.last("b.ply", "h2"), Some(Event::Started));
        assert_eq!(j.last("a.ply", "other"), None);
        j.record(Event::Done, "b.ply", "h2", "").unwrap();
        let j = Journal::open(dir.path()).unwrap();
        assert_eq!(j.last("b.ply", "h2"), Some(Event::Done));
    }
}
