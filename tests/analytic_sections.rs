//! Slicing analytic shapes: perimeter and tape girth within 0.05% of the closed-form values —
//! stacks of ellipses and superellipses (cut exactly through their vertex rings as well as
//! between them), and a non-star-shaped section.

use dressform::body::mesh::{Mesh, topology};
use dressform::body::slice::sections;
use glam::{DVec2, DVec3};
use std::f64::consts::{PI, TAU};

/// A closed "stack": ring k is `outline(k)` at height `z[k]`, with caps at both ends.
fn stack(rings: &[(f64, Vec<DVec2>)]) -> Mesh {
    let n = rings[0].1.len() as u32;
    let mut mesh = Mesh::default();
    for (z, ring) in rings {
        mesh.positions.extend(ring.iter().map(|p| p.extend(*z)));
    }
    for k in 0..rings.len() as u32 - 1 {
        for i in 0..n {
            let (a, b) = (k * n + i, k * n + (i + 1) % n);
            mesh.triangles.push([a, b, b + n]);
            mesh.triangles.push([a, b + n, a + n]);
        }
    }
    let bottom = mesh.positions.len() as u32;
    mesh.positions.push(DVec3::new(0.0, 0.0, rings[0].0));
    let top = bottom + 1;
    mesh.positions.push(DVec3::new(0.0, 0.0, rings[rings.len() - 1].0));
    let last = (rings.len() as u32 - 1) * n;
    for i in 0..n {
        mesh.triangles.push([bottom, (i + 1) % n, i]);
        mesh.triangles.push([top, last + i, last + (i + 1) % n]);
    }
    mesh
}

/// `m` points of the superellipse |x/a|^e + |y/b|^e = 1 (e = 2: an ellipse).
fn superellipse(a: f64, b: f64, e: f64, m: usize) -> Vec<DVec2> {
    (0..m)
        .map(|k| {
            let t = TAU * k as f64 / m as f64;
            let (c, s) = (t.cos(), t.sin());
            DVec2::new(
                a * c.signum() * c.abs().powf(2.0 / e),
                b * s.signum() * s.abs().powf(2.0 / e),
            )
        })
        .collect()
}

/// Ramanujan's second approximation of an ellipse's perimeter (relative error < 1e-9 here).
fn ellipse_perimeter(a: f64, b: f64) -> f64 {
    let h = ((a - b) / (a + b)).powi(2);
    PI * (a + b) * (1.0 + 3.0 * h / (10.0 + (4.0 - 3.0 * h).sqrt()))
}

/// A superellipse's perimeter by integration over 200,000 segments.
fn superellipse_perimeter(a: f64, b: f64, e: f64) -> f64 {
    let p = superellipse(a, b, e, 200_000);
    (0..p.len()).map(|i| p[i].distance(p[(i + 1) % p.len()])).sum()
}

fn assert_close(measured: f64, exact: f64, what: &str) {
    let rel = (measured - exact).abs() / exact;
    assert!(rel < 5e-4, "{what}: {measured:.4} vs {exact:.4} ({:.4}%)", 100.0 * rel);
}

#[test]
fn stacked_ellipses_and_superellipses() {
    let shapes = |z: f64| {
        let a = 160.0 + 40.0 * (z / 300.0).sin();
        (a, 0.7 * a)
    };
    for e in [2.0, 2.5, 4.0] {
        let zs: Vec<f64> = (0..=40).map(|k| 25.0 * k as f64).collect();
        let rings: Vec<(f64, Vec<DVec2>)> = zs
            .iter()
            .map(|&z| {
                let (a, b) = shapes(z);
                (z, superellipse(a, b, e, 2880))
            })
            .collect();
        let mesh = stack(&rings);
        assert!(topology(&mesh).is_closed() && mesh.signed_volume() > 0.0);
        // Exactly through vertex rings (every vertex on the plane) and between them.
        let cut: Vec<f64> = (1..40)
            .map(|k| 25.0 * k as f64)
            .chain((1..10).map(|k| 100.0 * k as f64 - 12.5))
            .collect();
        for s in sections(&mesh, &cut) {
            assert_eq!(s.loops.len(), 1, "z = {}", s.height);
            let on_ring = (s.height / 25.0).fract() == 0.0;
            let l = &s.loops[0];
            if on_ring {
                let (a, b) = shapes(s.height);
                let exact = if e == 2.0 {
                    ellipse_perimeter(a, b)
                } else {
                    superellipse_perimeter(a, b, e)
                };
                let what = format!("e = {e}, z = {}", s.height);
                assert_close(l.perimeter(), exact, &what);
                assert_close(l.tape_girth(), exact, &what); // convex: tape = contour
            } else {
                // Between rings the section is the linear blend of the two rings.
                let (below, above) = (
                    &rings[(s.height / 25.0) as usize].1,
                    &rings[(s.height / 25.0) as usize + 1].1,
                );
                let mid: Vec<DVec2> =
                    below.iter().zip(above).map(|(p, q)| (*p + *q) * 0.5).collect();
                let exact: f64 =
                    (0..mid.len()).map(|i| mid[i].distance(mid[(i + 1) % mid.len()])).sum();
                assert_close(l.perimeter(), exact, "between rings");
            }
        }
    }
}

#[test]
fn a_non_star_shaped_section() {
    // A "U" (no point sees its whole boundary): 300 wide, 200 deep, walls 60 thick.
    let u = [
        (0., 0.),
        (300., 0.),
        (300., 200.),
        (240., 200.),
        (240., 60.),
        (60., 60.),
        (60., 200.),
        (0., 200.),
    ];
    let outline: Vec<DVec2> = u.iter().map(|&(x, y)| DVec2::new(x - 150.0, y - 100.0)).collect();
    // Densify the outline so that the stack's rings have many points on every side.
    let dense: Vec<DVec2> = (0..outline.len())
        .flat_map(|i| {
            let (a, b) = (outline[i], outline[(i + 1) % outline.len()]);
            (0..50).map(move |k| a.lerp(b, k as f64 / 50.0))
        })
        .collect();
    let mesh = stack(&[(0.0, dense.clone()), (100.0, dense.clone()), (200.0, dense)]);
    let contour = 300.0 + 200.0 + 60.0 + 140.0 + 180.0 + 140.0 + 60.0 + 200.0;
    let tape = 2.0 * (300.0 + 200.0);
    for s in sections(&mesh, &[50.0, 100.0, 150.0]) {
        assert_eq!(s.loops.len(), 1);
        assert_close(s.loops[0].perimeter(), contour, "U contour");
        assert_close(s.loops[0].tape_girth(), tape, "U tape girth");
    }
}
