//! Issue 29, item 7: `reconstruct` of one scan gives the same bytes in every output file, run
//! after run and whatever the number of threads (a studio re-running a customer, or CI
//! comparing outputs, needs the same bytes). The pose fit's sums run in parallel; rayon groups
//! their additions as threads steal work, so only sums in a fixed order give the same bits; and
//! `fit.json` holds no wall time.

use crate::common::{output_files, surface_mesh};
use capture_sim::{Artifacts, BodyParams, capture, generate};
use dressform::body::scan::format::Format;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

/// How much further out `dressform demo`'s customer holds the left arm and stands on the right
/// leg (degrees), as the demo poses it (`cli::demo::ARM_FURTHER_OUT_DEG`,
/// `LEG_FURTHER_OUT_DEG`).
const ARM_FURTHER_OUT_DEG: f64 = 15.0;
const LEG_FURTHER_OUT_DEG: f64 = 5.0;

/// The demo's customer, standing asymmetrically, scanned as the demo scans it (the typical
/// scanner of seed 0), written to `dir/scan.ply`; generated once for both tests.
fn demo_scan(dir: &Path) -> PathBuf {
    static PLY: OnceLock<Vec<u8>> = OnceLock::new();
    let ply = PLY.get_or_init(|| {
        let mut params = BodyParams::default();
        params.pose.left_arm.abduction_deg += ARM_FURTHER_OUT_DEG;
        params.pose.right_leg.abduction_deg += LEG_FURTHER_OUT_DEG;
        let body = generate(&params).expect("the demo's customer generates");
        Format::Ply.encode(&surface_mesh(&capture(&body, &Artifacts::typical_scanner(0))))
    });
    let path = dir.join("scan.ply");
    std::fs::write(&path, ply).expect("writable");
    path
}

/// Runs `reconstruct` on `scan` into `dir/<name>` with `RAYON_NUM_THREADS` set to `threads`
/// (unset: rayon's default); returns the output files by name.
fn reconstruct(
    scan: &Path,
    dir: &Path,
    name: &str,
    threads: Option<&str>,
) -> Vec<(String, Vec<u8>)> {
    let out = dir.join(name);
    let mut command = std::process::Command::new(env!("CARGO_BIN_EXE_dressform"));
    command.args(["reconstruct", scan.to_str().unwrap(), "--out", out.to_str().unwrap()]);
    match threads {
        Some(n) => command.env("RAYON_NUM_THREADS", n),
        None => command.env_remove("RAYON_NUM_THREADS"),
    };
    let run = command.output().expect("the dressform binary runs");
    assert!(run.status.success(), "{name}: {}", String::from_utf8_lossy(&run.stderr));
    let files = output_files(&out);
    let names: Vec<&str> = files.iter().map(|(n, _)| n.as_str()).collect();
    assert_eq!(
        names,
        [
            "fit.json",
            "mannequin.obj",
            "measurements.json",
            "posed.obj",
            "preview.png",
            "profiles.json",
            "report.html",
            "rigged.glb",
            "sections.svg"
        ],
        "{name}"
    );
    files
}

/// Asserts that the runs `a` and `b` wrote the same bytes in every file; names each file that
/// differs, and where.
fn assert_same_bytes(a: &[(String, Vec<u8>)], b: &[(String, Vec<u8>)], what: &str) {
    let differing: Vec<String> = a
        .iter()
        .zip(b)
        .filter(|((_, x), (_, y))| x != y)
        .map(|((name, x), (_, y))| format!("{name} ({})", first_difference(x, y)))
        .collect();
    assert!(differing.is_empty(), "{what}: {}", differing.join("; "));
}

/// Where `x` and `y` first differ: the byte, and in a text file its line and the text around
/// it in each.
fn first_difference(x: &[u8], y: &[u8]) -> String {
    let at = x.iter().zip(y).position(|(p, q)| p != q).unwrap_or(x.len().min(y.len()));
    if std::str::from_utf8(x).is_err() {
        return format!("byte {at}");
    }
    let line = x[..at].iter().filter(|&&c| c == b'\n').count() + 1;
    let near = |f: &[u8]| {
        String::from_utf8_lossy(&f[at.saturating_sub(30).min(f.len())..(at + 30).min(f.len())])
            .into_owned()
    };
    format!("line {line}: {:?} | {:?}", near(x), near(y))
}

#[test]
fn reconstruct_twice_gives_the_same_bytes() {
    let tmp = tempfile::tempdir().unwrap();
    let scan = demo_scan(tmp.path());
    let first = reconstruct(&scan, tmp.path(), "first", None);
    let second = reconstruct(&scan, tmp.path(), "second", None);
    assert_same_bytes(&first, &second, "two runs differ");
}

#[test]
fn one_or_two_threads_give_the_same_bytes() {
    let tmp = tempfile::tempdir().unwrap();
    let scan = demo_scan(tmp.path());
    let one = reconstruct(&scan, tmp.path(), "one", Some("1"));
    let two = reconstruct(&scan, tmp.path(), "two", Some("2"));
    assert_same_bytes(&one, &two, "1 and 2 threads differ");
}
