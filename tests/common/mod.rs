//! Helpers shared by the integration tests.
#![allow(dead_code)] // each test binary uses a different subset

use std::path::PathBuf;

/// The MakeHuman assets (`$DRESSFORM_MAKEHUMAN`, else `../shared/makehuman` beside the
/// project), or `None` with a message when they are absent. With `DRESSFORM_REQUIRE_SHARED=1`
/// (as in CI) their absence fails the test instead of skipping it.
pub fn makehuman() -> Option<PathBuf> {
    let dir = std::env::var_os("DRESSFORM_MAKEHUMAN")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../shared/makehuman"));
    if dir.join("base.obj").is_file() {
        return Some(dir);
    }
    let required = std::env::var("DRESSFORM_REQUIRE_SHARED").is_ok_and(|v| v == "1");
    assert!(!required, "DRESSFORM_REQUIRE_SHARED=1 but {} has no base.obj", dir.display());
    eprintln!("SKIPPED: MakeHuman assets not found at {} (set DRESSFORM_MAKEHUMAN)", dir.display());
    None
}

/// Runs the `dressform` binary with `args`; returns (exit code, stdout, stderr).
pub fn dressform(args: &[&str]) -> (i32, String, String) {
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_dressform"))
        .args(args)
        .output()
        .expect("the dressform binary runs");
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}
