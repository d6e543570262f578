//! `preview.png` and `sections.svg` from `dressform symmetrize`: the picture shows the chest,
//! waist and hip lines at their heights on every body drawn, and the figure gives the girths
//! of `measurements.json`.

use crate::common;

use capture_sim::{BodyParams, generate};
use dressform::body::scan::format::Format;

/// The level lines' colours in the preview (chest, waist, hip), as documented in
/// `src/preview/mod.rs`, and how far a pixel may be from one to count (anti-aliasing).
const LEVEL_RGB: [[i32; 3]; 3] = [[214, 38, 40], [43, 160, 43], [30, 119, 181]];
const NEAR: i32 = 40;

/// Runs `symmetrize` on the default synthetic customer; returns the output directory.
fn symmetrized() -> tempfile::TempDir {
    let body = generate(&BodyParams::default()).unwrap();
    let mesh = common::mesh_of(&body);
    let dir = tempfile::tempdir().unwrap();
    let scan = dir.path().join("customer.ply");
    std::fs::write(&scan, Format::Ply.encode(&mesh)).unwrap();
    let (code, _, stderr) = common::dressform(&[
        "symmetrize",
        scan.to_str().unwrap(),
        "-o",
        dir.path().to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{stderr}");
    dir
}

#[test]
fn the_preview_draws_the_levels_at_their_heights_on_all_six_bodies() {
    let dir = symmetrized();
    let measurements: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.path().join("measurements.json")).unwrap())
            .unwrap();
    let z: Vec<f64> = ["chest", "waist", "hip"]
        .map(|k| measurements["levels"][format!("{k}_mm")].as_f64().unwrap())
        .to_vec();
    let png = image::load_from_memory(&std::fs::read(dir.path().join("preview.png")).unwrap())
        .unwrap()
        .to_rgb8();
    let (width, height) = png.dimensions();
    assert!(width > height, "the views side by side: {width} x {height}");
    // For each level: the rows and the runs of columns where its colour is.
    let mut rows = Vec::new();
    for colour in LEVEL_RGB {
        let near = |x: u32, y: u32| {
            let p = png.get_pixel(x, y).0;
            (0..3).all(|i| (i32::from(p[i]) - colour[i]).abs() <= NEAR)
        };
        // Where the level's line is: the row where most of its pixels are (the legend's
        // swatches sit below the bodies, in rows of their own).
        let count = |y: u32| (0..width).filter(|&x| near(x, y)).count();
        let row = (0..height).max_by_key(|&y| count(y)).unwrap();
        let columns: Vec<u32> =
            (0..width).filter(|&x| (row.saturating_sub(2)..=row + 2).any(|y| near(x, y))).collect();
        let runs = 1 + columns.windows(2).filter(|w| w[1] > w[0] + 1).count();
        assert!(runs >= 6, "a line on each of the six bodies: {runs} runs at row {row}");
        rows.push(f64::from(row));
    }
    assert!(rows[0] < rows[1] && rows[1] < rows[2], "chest above waist above hip: {rows:?}");
    // The same scale for heights and rows: the waist sits between chest and hip as on the body.
    let on_body = (z[0] - z[1]) / (z[0] - z[2]);
    let in_picture = (rows[1] - rows[0]) / (rows[2] - rows[0]);
    assert!((on_body - in_picture).abs() < 0.03, "waist at {in_picture:.3} vs {on_body:.3}");
}

#[test]
fn the_sections_figure_gives_the_girths_of_the_measurements() {
    let dir = symmetrized();
    let measurements: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.path().join("measurements.json")).unwrap())
            .unwrap();
    let svg = std::fs::read_to_string(dir.path().join("sections.svg")).unwrap();
    assert!(svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"));
    assert_eq!(svg.matches("<path").count(), 12, "four curves at each of three levels");
    for row in measurements["table"].as_array().unwrap() {
        let name = row["measure"].as_str().unwrap();
        let z = row["z_mm"].as_f64().unwrap();
        assert!(svg.contains(&format!("{name} (z = {z:.0} mm)")), "{name}");
        for (body, girth) in [("scan", &row["input"]), ("mannequin", &row["mannequin"])] {
            let text = format!("{body}: tape girth {:.1} mm", girth["tape_mm"].as_f64().unwrap());
            assert!(svg.contains(&text), "{text}");
        }
    }
    for (k, row) in measurements["mirrored"].as_array().unwrap().iter().enumerate().skip(1).take(2)
    {
        let body = row["body"].as_str().unwrap();
        for level in ["chest", "waist", "hip"] {
            let text = format!(
                "{body}: tape girth {:.1} mm",
                row[format!("{level}_mm")].as_f64().unwrap()
            );
            assert!(svg.contains(&text), "Fig. 11 row {k}: {text}");
        }
    }
}
