//! `report.html`, the customer report (issue 33): the demo writes it, and `--report` a copy;
//! it stands alone (nothing fetched, no script); every measurement `measure` reports has its
//! row; headless Chromium (Debian's `chromium`, driven by npm `playwright-core` through
//! `tests/common/check_report.js`) opens it with the network refused and JavaScript off with
//! no console or page errors, every picture loaded, and a first A4 page a person can read.

// Runs the demo (the `simulator` feature).
#![cfg(feature = "simulator")]

use crate::common;
use std::path::{Path, PathBuf};

/// The A4 page the checker screenshots, in CSS pixels (210 x 297 mm at 96 per inch).
const A4_PX: (u32, u32) = (794, 1123);
/// A screenshot's pixels darker than this (of 255) are ink: text, lines, pictures.
const INK_BELOW: u8 = 200;
/// The least share of a readable first page that is ink: on the demo's, its header, the
/// bodies' picture, the sections and the table's start make 9%; a blank page has none.
const MIN_INK: f64 = 0.03;

/// What headless Chromium saw of `report` (the checker's JSON), its first A4 page saved to
/// `screenshot`; `None` (skipped, or failing with `DRESSFORM_REQUIRE_PEERS=1`) when node,
/// playwright-core or Chromium is missing.
fn open_in_chromium(report: &Path, screenshot: &Path) -> Option<serde_json::Value> {
    let script = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/common/check_report.js");
    let run = std::process::Command::new("node").arg(script).arg(report).arg(screenshot).output();
    let found = match run {
        Err(e) => Err(format!("cannot run node: {e}")),
        // The checker's "unavailable": playwright-core or the browser is missing.
        Ok(out) if out.status.code() == Some(2) => {
            Err(String::from_utf8_lossy(&out.stderr).trim().to_string())
        }
        Ok(out) => {
            let stderr = String::from_utf8_lossy(&out.stderr);
            assert!(out.status.success(), "check_report.js failed: {stderr}");
            Ok(serde_json::from_slice(&out.stdout).expect("the checker's JSON"))
        }
    };
    let what = "headless Chromium (Debian chromium, npm playwright-core)";
    common::or_skip(found, what, "DRESSFORM_REQUIRE_PEERS")
}

#[test]
fn the_demo_report_stands_alone_and_renders_in_chromium() {
    let tmp = tempfile::tempdir().unwrap();
    let (out, copy) = (tmp.path().join("demo"), tmp.path().join("customer.html"));
    let args = ["demo", "--out", out.to_str().unwrap(), "--report", copy.to_str().unwrap()];
    let (code, _, stderr) = common::dressform(&args);
    assert_eq!(code, 0, "{stderr}");
    let report = out.join("report.html");
    let html = std::fs::read_to_string(&report).unwrap();
    assert_eq!(std::fs::read_to_string(&copy).unwrap(), html, "--report: the same report");

    // Nothing to fetch: the only URLs are the SVG namespace's name; no script.
    for (at, _) in html.match_indices("http") {
        let around = &html[at.saturating_sub(7)..(at + 40).min(html.len())];
        assert!(around.starts_with("xmlns=\"http://www.w3.org/"), "a resource: {around}");
    }
    assert!(!html.contains("<script") && !html.contains("@import"), "no script, no import");
    // The customer, the pictures inline, the parts.
    for part in [
        "synthetic customer (the demo's own)",
        "data:image/png;base64,",
        "<svg viewBox=",
        "id=\"body\"",
        "id=\"measurements\"",
        "id=\"form\"",
        "@page { size: A4;",
    ] {
        assert!(html.contains(part), "{part} missing");
    }
    // Every dimension `measure` reports on the pose-symmetric scan has its row.
    let posed = out.join("posed.obj");
    let (code, json, stderr) =
        common::dressform(&["measure", posed.to_str().unwrap(), "--json", "--smooth", "0"]);
    assert_eq!(code, 0, "{stderr}");
    let json: serde_json::Value = serde_json::from_str(&json).unwrap();
    let dimensions = json["dimensions"].as_object().expect("measure's dimensions");
    for key in dimensions.keys() {
        assert!(html.contains(&format!("<tr id=\"{key}\"")), "no row for {key}");
    }
    let rows = html.matches("<tr id=\"").count();
    assert_eq!(rows, dimensions.len(), "a row for each dimension, no more");

    // In the browser.
    let screenshot = tmp.path().join("a4.png");
    let Some(seen) = open_in_chromium(&report, &screenshot) else { return };
    for kind in ["consoleErrors", "pageErrors", "requests"] {
        assert_eq!(seen[kind].as_array().map(Vec::len), Some(0), "{kind}: {seen:#}");
    }
    let images = seen["images"].as_array().unwrap();
    assert_eq!(images.len(), 2, "preview.png and form-fit.png: {seen:#}");
    for image in images {
        let loaded = image["complete"] == true && image["naturalWidth"].as_f64() > Some(0.0);
        assert!(loaded, "not loaded: {image}");
    }
    let svgs = seen["svgs"].as_array().unwrap();
    assert_eq!(svgs.len(), 1, "sections.svg: {seen:#}");
    for svg in svgs {
        assert!(svg["width"].as_f64() > Some(0.0) && svg["height"].as_f64() > Some(0.0), "{svg}");
    }
    let page = image::open(&screenshot).unwrap().to_luma8();
    assert_eq!(page.dimensions(), A4_PX);
    let ink = page.pixels().filter(|p| p[0] < INK_BELOW).count();
    let share = ink as f64 / f64::from(A4_PX.0 * A4_PX.1);
    assert!(share > MIN_INK, "the first page is nearly blank: {:.1}% ink", 100.0 * share);
}
