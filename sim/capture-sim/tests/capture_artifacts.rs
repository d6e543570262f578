//! Scanner artifacts: exact unit and axis conversions, holes at the requested places, noise
//! of the requested deviation, determinism. (That each hole is one simple boundary loop is
//! checked with dressform's topology in the root crate's `tests/synthetic_bodies.rs`.)

use std::sync::OnceLock;

use capture_sim::{
    Artifacts, BodyParams, HoleSite, SyntheticBody, Units, UpAxis, capture, generate,
};

/// One default body shared by the tests of this file (generated once).
fn body() -> &'static SyntheticBody {
    static BODY: OnceLock<SyntheticBody> = OnceLock::new();
    BODY.get_or_init(|| generate(&BodyParams::default()).expect("default body"))
}

#[test]
fn clean_capture_is_the_body_surface() {
    let b = body();
    assert_eq!(capture(b, &Artifacts::default()), b.surface);
}

#[test]
fn units_and_up_axis_conversions_are_exact() {
    let b = body();
    for units in [Units::M, Units::Dm, Units::Cm, Units::Mm] {
        for up in [UpAxis::Y, UpAxis::Z] {
            let artifacts = Artifacts { units, up, ..Artifacts::default() };
            let s = capture(b, &artifacts);
            assert_eq!(s.triangles, b.surface.triangles);
            let k = units.mm_per_unit();
            for (p, q) in b.surface.positions.iter().zip(&s.positions) {
                let expected = match up {
                    UpAxis::Z => [p[0] / k, p[1] / k, p[2] / k],
                    UpAxis::Y => [p[0] / k, p[2] / k, -p[1] / k],
                };
                assert_eq!(*q, expected);
            }
        }
    }
    assert_eq!(Units::M.mm_per_unit(), 1000.0);
    assert_eq!(Units::Dm.mm_per_unit(), 100.0);
    assert_eq!(Units::Cm.mm_per_unit(), 10.0);
}

#[test]
fn y_up_capture_faces_plus_z_and_stands_on_y() {
    let b = body();
    let s = capture(b, &Artifacts { units: Units::M, up: UpAxis::Y, ..Artifacts::default() });
    let (lo, hi) = s.bounds().expect("vertices");
    assert!((hi[1] - b.truth.height_mm / 1000.0).abs() < 1e-3);
    assert!(lo[1].abs() < 1e-3);
    // The nose points to +Z, like MakeHuman's.
    let nose = b.truth.landmarks.nose_tip;
    let nose_y_up = [nose[0], nose[2], -nose[1]];
    assert!(nose_y_up[2] > 0.0);
    let front = s.positions.iter().filter(|p| p[1] > 1.4).map(|p| p[2]).fold(f64::MIN, f64::max);
    assert!((front - nose_y_up[2] / 1000.0).abs() < 2e-3);
}

#[test]
fn yaw_turns_about_the_vertical() {
    let b = body();
    let s = capture(b, &Artifacts { yaw_deg: 90.0, ..Artifacts::default() });
    for (p, q) in b.surface.positions.iter().zip(&s.positions) {
        // Counter-clockwise from above: +X goes to +Y.
        assert!((q[0] + p[1]).abs() < 1e-9 && (q[1] - p[0]).abs() < 1e-9);
        assert_eq!(q[2], p[2]);
    }
}

#[test]
fn holes_are_where_the_sites_are() {
    let b = body();
    let s = capture(
        b,
        &Artifacts { holes: vec![HoleSite::Crotch], hole_radius_mm: 25.0, ..Artifacts::default() },
    );
    let crotch = b.truth.landmarks.crotch;
    let near = |p: &[f64; 3]| (0..3).map(|i| (p[i] - crotch[i]).powi(2)).sum::<f64>().sqrt() < 15.0;
    assert!(b.surface.positions.iter().any(near));
    assert!(!s.positions.iter().any(near));
}

#[test]
fn noise_has_the_requested_deviation_and_is_seeded() {
    let b = body();
    let sigma = 1.5;
    let noisy =
        |seed| capture(b, &Artifacts { noise_sigma_mm: sigma, seed, ..Artifacts::default() });
    let s = noisy(7);
    assert_eq!(s.triangles, b.surface.triangles);
    let moves: Vec<f64> = b
        .surface
        .positions
        .iter()
        .zip(&s.positions)
        .map(|(p, q)| (0..3).map(|i| (q[i] - p[i]).powi(2)).sum::<f64>().sqrt())
        .collect();
    let rms = (moves.iter().map(|d| d * d).sum::<f64>() / moves.len() as f64).sqrt();
    assert!((rms / sigma - 1.0).abs() < 0.02, "rms {rms}");
    // Each vertex moved along its normal.
    let normals = b.surface.vertex_normals();
    for ((p, q), n) in b.surface.positions.iter().zip(&s.positions).zip(&normals) {
        let d = [q[0] - p[0], q[1] - p[1], q[2] - p[2]];
        let along = d[0] * n[0] + d[1] * n[1] + d[2] * n[2];
        let across: f64 = (0..3).map(|i| (d[i] - along * n[i]).powi(2)).sum();
        assert!(across.sqrt() < 1e-9);
    }
    assert_eq!(noisy(7), s);
    assert_ne!(noisy(8), s);
    // No noise for zero or invalid deviations.
    for bad in [0.0, -1.0, f64::NAN] {
        let clean = capture(b, &Artifacts { noise_sigma_mm: bad, ..Artifacts::default() });
        assert_eq!(clean, b.surface);
    }
}
