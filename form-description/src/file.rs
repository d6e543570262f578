//! Descriptions as TOML files: reading (parse, then validate), writing, the shipped
//! reference form, and why a file could not be used.

use std::path::{Path, PathBuf};

use super::description::{FormDescription, FormSpec};
use super::validate::Problem;

/// The reference form's description, as shipped in `forms/reference.toml`.
pub const REFERENCE_TOML: &str = include_str!("../forms/reference.toml");

/// The male reference form's description, as shipped in `forms/male.toml`.
pub const MALE_TOML: &str = include_str!("../forms/male.toml");

/// The built-in forms by name, with their descriptions: `reference` (the default) and
/// `male`.
pub const BUILTIN: [(&str, &str); 2] = [("reference", REFERENCE_TOML), ("male", MALE_TOML)];

/// The shipped reference form: 64 panel actuators on 8 nodes from neck to mid-thigh and 8
/// lifts on a ninth (see `form-description/README.md` for its layout).
pub fn reference() -> FormDescription {
    builtin("reference").unwrap_or_else(|| unreachable!("the reference form is built in"))
}

/// The description file of the built-in form named `name` (see [`BUILTIN`]), with its
/// comments, if there is one.
pub fn builtin_toml(name: &str) -> Option<&'static str> {
    BUILTIN.iter().find(|(n, _)| *n == name).map(|(_, text)| *text)
}

/// The built-in form named `name` (see [`BUILTIN`]), if there is one.
pub fn builtin(name: &str) -> Option<FormDescription> {
    let text = builtin_toml(name)?;
    // The files are part of the crate and a test checks they validate.
    Some(
        FormDescription::from_toml_str(text)
            .unwrap_or_else(|error| unreachable!("the built-in form {name} is invalid: {error}")),
    )
}

impl FormDescription {
    /// Parses and validates a TOML description.
    pub fn from_toml_str(text: &str) -> Result<Self, FormError> {
        let spec: FormSpec =
            toml::from_str(text).map_err(|source| FormError::Toml { path: None, source })?;
        Self::try_from(spec).map_err(|problems| FormError::Invalid { path: None, problems })
    }

    /// Reads, parses and validates a TOML description file; errors name the file.
    pub fn load(path: impl AsRef<Path>) -> Result<Self, FormError> {
        let path = path.as_ref();
        let text = std::fs::read_to_string(path)
            .map_err(|source| FormError::Io { path: path.to_owned(), source })?;
        Self::from_toml_str(&text).map_err(|error| match error {
            FormError::Toml { source, .. } => FormError::Toml { path: Some(path.into()), source },
            FormError::Invalid { problems, .. } => {
                FormError::Invalid { path: Some(path.into()), problems }
            }
            io => io,
        })
    }

    /// The description as TOML (what [`from_toml_str`](Self::from_toml_str) reads back).
    pub fn to_toml_string(&self) -> String {
        // Plain structs of strings, numbers and arrays always serialise.
        toml::to_string(self).unwrap_or_default()
    }
}

/// Why a form description could not be used.
#[derive(Debug, thiserror::Error)]
pub enum FormError {
    /// The file could not be read.
    #[error("cannot read form description {}: {source}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// Why.
        source: std::io::Error,
    },
    /// Not TOML, or not the shape of a form description (the message names the field).
    #[error("{}{source}", origin(path))]
    Toml {
        /// The file, if read from one.
        path: Option<PathBuf>,
        /// The parser's error, with line, column and field.
        source: toml::de::Error,
    },
    /// Well-formed but inconsistent: every problem found.
    #[error("{}invalid form description:{}", origin(path), list(problems))]
    Invalid {
        /// The file, if read from one.
        path: Option<PathBuf>,
        /// Every problem, in file order.
        problems: Vec<Problem>,
    },
}

fn origin(path: &Option<PathBuf>) -> String {
    path.as_ref().map(|p| format!("{}: ", p.display())).unwrap_or_default()
}

fn list(problems: &[Problem]) -> String {
    problems.iter().map(|p| format!("\n  - {p}")).collect()
}
