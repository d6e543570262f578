//! The indexed triangle surface the capture hands over.

use std::io::{self, Write};

/// An indexed triangle mesh. `generate` returns it welded (one vertex per position), closed
/// and manifold, each triangle counter-clockwise seen from outside (normals point outward).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct TriangleSurface {
    /// Vertex positions.
    pub positions: Vec<[f64; 3]>,
    /// Triangles as indices into `positions`.
    pub triangles: Vec<[u32; 3]>,
}

impl TriangleSurface {
    /// Unit vertex normals: the area-weighted sum of the normals of the triangles around each
    /// vertex (zero for a vertex no triangle uses).
    pub fn vertex_normals(&self) -> Vec<[f64; 3]> {
        let mut normals = vec![[0.0f64; 3]; self.positions.len()];
        for t in &self.triangles {
            let [a, b, c] = t.map(|i| self.positions[i as usize]);
            let u = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
            let v = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
            // Twice the area times the unit normal.
            let n =
                [u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]];
            for &i in t {
                for (s, x) in normals[i as usize].iter_mut().zip(n) {
                    *s += x;
                }
            }
        }
        for n in &mut normals {
            let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
            if len > 0.0 {
                n.iter_mut().for_each(|x| *x /= len);
            }
        }
        normals
    }

    /// Axis-aligned bounds (min, max) of the vertices; `None` when there are none.
    pub fn bounds(&self) -> Option<([f64; 3], [f64; 3])> {
        let first = *self.positions.first()?;
        Some(self.positions.iter().fold((first, first), |(lo, hi), p| {
            (
                [lo[0].min(p[0]), lo[1].min(p[1]), lo[2].min(p[2])],
                [hi[0].max(p[0]), hi[1].max(p[1]), hi[2].max(p[2])],
            )
        }))
    }

    /// Writes the surface as a Wavefront OBJ (`v` and `f` lines, 1-based indices).
    pub fn write_obj(&self, out: &mut impl Write) -> io::Result<()> {
        for p in &self.positions {
            writeln!(out, "v {} {} {}", p[0], p[1], p[2])?;
        }
        for t in &self.triangles {
            writeln!(out, "f {} {} {}", t[0] + 1, t[1] + 1, t[2] + 1)?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn normals_of_a_tetrahedron_point_away_from_it() {
        let s = TriangleSurface {
            positions: vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
            triangles: vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]],
        };
        let n = s.vertex_normals();
        assert!(n[0].iter().all(|&x| x < 0.0));
        assert!(n[3][2] > 0.0);
        let mut obj = Vec::new();
        s.write_obj(&mut obj).unwrap();
        let text = String::from_utf8(obj).unwrap();
        assert_eq!(text.lines().count(), 8);
        assert!(text.contains("f 2 3 4"));
        assert_eq!(s.bounds(), Some(([0.0; 3], [1.0; 3])));
    }
}
