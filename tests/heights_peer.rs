//! The lifts' heights solver (`form_fit::heights::bounded_least_squares`) against SciPy's
//! bounded least squares (`scipy.optimize.lsq_linear`, method "bvls"): on 60 problems of the
//! shapes a form's lifts give (0/1 matrices: chains like the reference form's spine, and any
//! rings carried by any lifts, some columns alike) with levels above and below the strokes,
//! dressform's answer stays in the box and its sum of squares is never larger than SciPy's.

use crate::common;
use dressform::form::form_fit::heights::bounded_least_squares;
use nalgebra::{DMatrix, DVector};
use std::io::Write;
use std::process::{Command, Stdio};

/// A deterministic stream of numbers in [0, 1) (a 64-bit LCG, Knuth's MMIX constants):
/// enough for test cases, and no dependency.
struct Stream(u64);

impl Stream {
    fn next(&mut self) -> f64 {
        self.0 = self.0.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// Problem `k`: (A, b, upper).
fn problem(k: u64, s: &mut Stream) -> (DMatrix<f64>, DVector<f64>, Vec<f64>) {
    let rows = 1 + (s.next() * 10.0) as usize;
    let cols = 1 + (s.next() * 8.0) as usize;
    let chain = k.is_multiple_of(2);
    let a = DMatrix::from_fn(rows, cols, |r, c| {
        let carried = if chain { c <= r } else { s.next() < 0.5 };
        if carried { 1.0 } else { 0.0 }
    });
    let b = DVector::from_fn(rows, |_, _| -100.0 + 300.0 * s.next());
    let upper = (0..cols).map(|_| 1.0 + 150.0 * s.next()).collect();
    (a, b, upper)
}

#[test]
fn the_heights_solver_is_as_good_as_scipys_bvls() {
    let found = common::python_modules("numpy, scipy");
    if common::or_skip(found, "python3 with numpy and scipy", "DRESSFORM_REQUIRE_PEERS").is_none() {
        return;
    }
    let mut stream = Stream(31);
    let problems: Vec<_> = (0..60).map(|k| problem(k, &mut stream)).collect();
    let json: Vec<serde_json::Value> = problems
        .iter()
        .map(|(a, b, upper)| {
            let rows: Vec<Vec<f64>> =
                (0..a.nrows()).map(|r| a.row(r).iter().copied().collect()).collect();
            serde_json::json!({ "a": rows, "b": b.as_slice(), "upper": upper })
        })
        .collect();
    let script = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/scripts/bvls_peer.py");
    let mut child = Command::new("python3")
        .arg(script)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .spawn()
        .unwrap();
    child
        .stdin
        .take()
        .unwrap()
        .write_all(serde_json::to_string(&json).unwrap().as_bytes())
        .unwrap();
    let out = child.wait_with_output().unwrap();
    assert!(out.status.success(), "bvls_peer.py failed");
    let answers: Vec<serde_json::Value> = serde_json::from_slice(&out.stdout).unwrap();
    for (k, ((a, b, upper), answer)) in problems.iter().zip(&answers).enumerate() {
        let x = bounded_least_squares(a, b, upper);
        for (xi, ui) in x.iter().zip(upper) {
            assert!((0.0..=*ui).contains(xi), "problem {k}: {x:?} outside 0..={upper:?}");
        }
        let ours = (a * DVector::from_column_slice(&x) - b).norm_squared();
        let scipy = answer["cost"].as_f64().unwrap();
        assert!(
            ours <= scipy + 1e-6 * (1.0 + scipy),
            "problem {k}: {ours} against SciPy's {scipy}"
        );
    }
}
