//! What every mesh-reader target checks: reading never panics; a mesh that is read has every
//! index in range, and cleaning and the topology analysis run on it without panicking.

use dressform::body::scan::format::Format;

pub fn check(format: Format, bytes: &[u8]) {
    let Ok(file) = format.decode(bytes) else { return };
    let n = file.mesh.positions.len() as u64;
    assert!(file.mesh.triangles.iter().flatten().all(|&i| u64::from(i) < n));
    let _ = dressform::body::mesh::topology(&file.mesh);
    let _ = dressform::body::scan::clean::clean(file.mesh);
}
