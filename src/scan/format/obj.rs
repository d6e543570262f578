//! Wavefront OBJ through `tobj`: positions and faces only (normals, UVs and materials are not
//! needed by the pipeline). Every group becomes part of one mesh; vertices that groups share
//! are joined again by welding in [`crate::scan::clean`].

use super::ReadError;
use crate::mesh::Mesh;
use glam::DVec3;
use std::fmt::Write as _;

pub(super) fn read(bytes: &[u8]) -> Result<Mesh, ReadError> {
    let options = tobj::LoadOptions {
        triangulate: true,
        single_index: false,
        ignore_points: true,
        ignore_lines: true,
    };
    let mut reader = bytes;
    let (models, _) = tobj::load_obj_buf(&mut reader, &options, |_| {
        Err(tobj::LoadError::OpenFileFailed) // materials are not needed
    })
    .map_err(|e| ReadError::Malformed(e.to_string()))?;

    let mut mesh = Mesh::default();
    for model in models {
        let m = model.mesh;
        let base = mesh.positions.len() as u64;
        let local = m.positions.len() / 3;
        for (face, tri) in m.indices.chunks_exact(3).enumerate() {
            if let Some(&i) = tri.iter().find(|&&i| i as usize >= local) {
                return Err(ReadError::IndexOutOfRange { face, index: i.into(), vertices: local });
            }
            let global = [0, 1, 2].map(|k| u64::from(tri[k]) + base);
            let tri = global.map(|i| u32::try_from(i).unwrap_or(u32::MAX));
            if tri.contains(&u32::MAX) {
                return Err(ReadError::Malformed("more than 4 billion vertices".into()));
            }
            mesh.triangles.push(tri);
        }
        mesh.positions.extend(m.positions.chunks_exact(3).map(|p| DVec3::new(p[0], p[1], p[2])));
    }
    Ok(mesh)
}

/// ASCII OBJ; `f64` printed in Rust's shortest round-trip form, so reading it back is exact.
pub(super) fn encode(mesh: &Mesh) -> Vec<u8> {
    let mut s = String::with_capacity(mesh.positions.len() * 40 + mesh.triangles.len() * 24);
    s.push_str("# written by dressform\n");
    for p in &mesh.positions {
        let _ = writeln!(s, "v {} {} {}", p.x, p.y, p.z);
    }
    for t in &mesh.triangles {
        let _ = writeln!(s, "f {} {} {}", t[0] + 1, t[1] + 1, t[2] + 1);
    }
    s.into_bytes()
}
