//! Mean value coordinates in 3D (Ju, Schaefer, Warren, "Mean Value Coordinates for Closed
//! Triangular Meshes", 2005), the paper's eq. 1: weights `m_i(x)` of a point `x` with respect to
//! the vertices `v_i` of a closed, consistently oriented triangle mesh such that
//! `sum_i m_i v_i = x` (linear precision), for points inside and outside alike. Weights may be
//! negative where the mesh is not convex; they are still exact.
//!
//! The numerically stable angle form is used (`theta = 2 asin(l / 2)` from chord lengths of
//! unit vectors); a point on a vertex gets that vertex's weight 1, a point on a face the face's
//! barycentric coordinates.

use crate::body::mesh::Mesh;
use glam::DVec3;
use std::f64::consts::PI;

/// Closer than this (relative to the mesh's size) a point is taken to lie on a vertex or face.
const ON_SURFACE: f64 = 1e-12;

/// The mean value coordinates of `x` with respect to the vertices of the closed mesh `mesh`
/// (one weight per vertex, summing to 1).
pub fn coordinates(mesh: &Mesh, x: DVec3) -> Vec<f64> {
    let size = mesh.bounds().map_or(1.0, |b| b.size().length());
    let eps = ON_SURFACE * size;
    let n = mesh.positions.len();
    let mut distance = vec![0.0; n];
    let mut unit = vec![DVec3::ZERO; n];
    for (i, &p) in mesh.positions.iter().enumerate() {
        let d = p.distance(x);
        if d < eps {
            let mut w = vec![0.0; n];
            w[i] = 1.0;
            return w;
        }
        distance[i] = d;
        unit[i] = (p - x) / d;
    }
    let mut w = vec![0.0; n];
    for tri in &mesh.triangles {
        let v = tri.map(|i| i as usize);
        let u = v.map(|i| unit[i]);
        let d = v.map(|i| distance[i]);
        // theta_i: the angle subtended at x by the edge opposite corner i.
        let theta: [f64; 3] = std::array::from_fn(|i| {
            let chord = (u[(i + 1) % 3] - u[(i + 2) % 3]).length();
            2.0 * (chord / 2.0).min(1.0).asin()
        });
        let h = (theta[0] + theta[1] + theta[2]) / 2.0;
        if PI - h < ON_SURFACE.sqrt() {
            // x lies on this triangle (the angles span a half-plane): barycentric coordinates,
            // from the areas of the sub-triangles (exact on an edge too).
            let p = v.map(|i| mesh.positions[i]);
            let normal = (p[1] - p[0]).cross(p[2] - p[0]);
            let bary: [f64; 3] = std::array::from_fn(|i| {
                (p[(i + 1) % 3] - x).cross(p[(i + 2) % 3] - x).dot(normal).max(0.0)
            });
            let total: f64 = bary.iter().sum();
            let mut w = vec![0.0; n];
            for i in 0..3 {
                w[v[i]] += bary[i] / total;
            }
            return w;
        }
        let c: [f64; 3] = std::array::from_fn(|i| {
            2.0 * h.sin() * (h - theta[i]).sin()
                / (theta[(i + 1) % 3].sin() * theta[(i + 2) % 3].sin())
                - 1.0
        });
        let sign = u[0].dot(u[1].cross(u[2])).signum();
        let s: [f64; 3] = std::array::from_fn(|i| sign * (1.0 - c[i] * c[i]).max(0.0).sqrt());
        if s.iter().any(|si| si.abs() <= ON_SURFACE) {
            // x lies in the triangle's plane, outside it: the triangle contributes nothing.
            continue;
        }
        for i in 0..3 {
            let (next, prev) = ((i + 1) % 3, (i + 2) % 3);
            w[v[i]] += (theta[i] - c[next] * theta[prev] - c[prev] * theta[next])
                / (d[i] * theta[next].sin() * s[prev]);
        }
    }
    let total: f64 = w.iter().sum();
    w.iter_mut().for_each(|wi| *wi /= total);
    w
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An axis-aligned box with corners `lo` and `hi`, triangles facing outwards.
    fn cube(lo: f64, hi: f64) -> Mesh {
        let p = |i: usize| {
            DVec3::new(
                if i & 1 == 0 { lo } else { hi },
                if i & 2 == 0 { lo } else { hi },
                if i & 4 == 0 { lo } else { hi },
            )
        };
        let quads =
            [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]];
        Mesh::new(
            (0..8).map(p).collect(),
            quads.iter().flat_map(|&[a, b, c, d]| [[a, b, c], [a, c, d]]).collect(),
        )
    }

    #[test]
    fn a_vertex_a_point_on_an_edge_and_the_centre_are_reproduced() {
        let m = cube(0.0, 1.0);
        assert_eq!(coordinates(&m, DVec3::ONE), {
            let mut w = vec![0.0; 8];
            w[7] = 1.0;
            w
        });
        // The centre of the z = 0 face, on the diagonal of its two triangles.
        let w = coordinates(&m, DVec3::new(0.5, 0.5, 0.0));
        let back: DVec3 = (0..8).map(|i| w[i] * m.positions[i]).sum();
        assert!(back.distance(DVec3::new(0.5, 0.5, 0.0)) < 1e-12, "{back}");
        assert!(w.iter().all(|&wi| wi >= 0.0));
        // The cube's centre: reproduced, with positive weights (a convex mesh); the corners on
        // the diagonals of the split faces weigh more than the others.
        let w = coordinates(&m, DVec3::splat(0.5));
        let back: DVec3 = (0..8).map(|i| w[i] * m.positions[i]).sum();
        assert!(back.distance(DVec3::splat(0.5)) < 1e-12 && w.iter().all(|&wi| wi > 0.0), "{w:?}");
    }
}
