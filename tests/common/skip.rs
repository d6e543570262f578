//! Skip a test whose tool or data is missing, with a message, unless the environment says it
//! is required (`DRESSFORM_REQUIRE_*=1`, as CI sets them): then the test fails. The one place
//! that decides "skip or fail", for every crate's test binary (`sim/form-sim/tests/main.rs` and
//! `firmware-protocol/tests/main.rs` include this file by path).

use std::process::Command;

/// Whether the environment variable `var` is set to `1`.
fn required(var: &str) -> bool {
    std::env::var(var).is_ok_and(|v| v == "1")
}

/// `Some(found)`, or `None` after printing why the test is skipped; with `require_var=1` (as
/// in CI) a missing `what` fails the test instead.
pub fn or_skip<T>(found: Result<T, String>, what: &str, require_var: &str) -> Option<T> {
    match found {
        Ok(t) => Some(t),
        Err(why) => {
            assert!(!required(require_var), "{require_var}=1 but {what} is unavailable: {why}");
            eprintln!("SKIPPED: {what} is unavailable: {why}");
            None
        }
    }
}

/// Whether `python3` imports `modules` (`"can, serial"`); `Err` says why not. For
/// [`or_skip`] with `DRESSFORM_REQUIRE_PEERS`.
pub fn python_modules(modules: &str) -> Result<(), String> {
    let probe = Command::new("python3").args(["-c", &format!("import {modules}")]).output();
    match probe {
        Ok(out) if out.status.success() => Ok(()),
        Ok(out) => Err(String::from_utf8_lossy(&out.stderr).trim().to_string()),
        Err(e) => Err(format!("python3: {e}")),
    }
}
