//! Reading the JSON files a user hands dressform (set-points, profiles): one error that names
//! the file and what is wrong with it.

use std::path::{Path, PathBuf};

use serde::de::DeserializeOwned;

use crate::messages;

/// Why an input file cannot be used.
#[derive(Debug, thiserror::Error)]
pub enum InputError {
    /// It cannot be read.
    #[error("{}: cannot read: {source}", path.display())]
    Read {
        /// The file.
        path: PathBuf,
        /// Why.
        source: std::io::Error,
    },
    /// It is not a file of the expected kind.
    #[error("{}: not a {kind} file: {message}", path.display())]
    Syntax {
        /// The file.
        path: PathBuf,
        /// The kind expected (`set-point`, `profiles`).
        kind: &'static str,
        /// What the JSON parser said (with line and column).
        message: String,
    },
    /// It is such a file, but its content cannot be used.
    #[error("{}: {}", path.display(), summary(problems))]
    Invalid {
        /// The file.
        path: PathBuf,
        /// Every problem, each naming its field.
        problems: Vec<String>,
    },
}

/// Reads `path`.
pub fn read(path: &Path) -> Result<String, InputError> {
    std::fs::read_to_string(path)
        .map_err(|source| InputError::Read { path: path.to_path_buf(), source })
}

/// Parses `text`, the content of the `kind` file `path`, as JSON.
pub fn parse<T: DeserializeOwned>(
    text: &str,
    path: &Path,
    kind: &'static str,
) -> Result<T, InputError> {
    serde_json::from_str(text).map_err(|e| InputError::Syntax {
        path: path.to_path_buf(),
        kind,
        message: e.to_string(),
    })
}

/// `problems` found in `path`, if any, as an error.
pub fn check(path: &Path, problems: Result<(), Vec<String>>) -> Result<(), InputError> {
    problems.map_err(|problems| InputError::Invalid { path: path.to_path_buf(), problems })
}

/// `problems` for a message: the one, or how many and the first ones (see
/// [`messages::separated`]).
fn summary(problems: &[String]) -> String {
    match problems {
        [one] => one.clone(),
        _ => format!("{} problems: {}", problems.len(), messages::separated(problems, "; ")),
    }
}
