//! Helpers shared by the integration tests.
#![allow(dead_code)] // each test binary uses a different subset

use std::path::PathBuf;

pub mod frontal;
pub mod makehuman_scan;
pub mod quality;
mod skip;

pub use skip::{or_skip, python_modules};

/// The MakeHuman assets (`$DRESSFORM_MAKEHUMAN`, else `../shared/makehuman` beside the
/// project), or `None` with a message when they are absent. With `DRESSFORM_REQUIRE_SHARED=1`
/// (as in CI) their absence fails the test instead of skipping it.
pub fn makehuman() -> Option<PathBuf> {
    let dir = std::env::var_os("DRESSFORM_MAKEHUMAN")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../shared/makehuman"));
    let found = if dir.join("base.obj").is_file() {
        Ok(dir.clone())
    } else {
        Err(format!("{} has no base.obj (set DRESSFORM_MAKEHUMAN)", dir.display()))
    };
    or_skip(found, "the MakeHuman assets", "DRESSFORM_REQUIRE_SHARED")
}

/// What the Khronos glTF validator said about a file.
#[derive(Debug)]
pub struct GltfReport {
    pub errors: u64,
    pub warnings: u64,
    /// The validator's whole report (JSON), for messages.
    pub json: serde_json::Value,
}

/// Runs the Khronos glTF validator (npm `gltf-validator`, found through `$NODE_PATH` as
/// `.ci/run` installs it) on `file`; `None` (skipped, or failing with
/// `DRESSFORM_REQUIRE_PEERS=1`) when node or the validator is missing.
pub fn validate_gltf(file: &std::path::Path) -> Option<GltfReport> {
    let script = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/common/validate_gltf.js");
    let run = std::process::Command::new("node").arg(&script).arg(file).output();
    let found = match run {
        Err(e) => Err(format!("cannot run node: {e}")),
        Ok(out) if !out.status.success() => {
            Err(format!("node: {}", String::from_utf8_lossy(&out.stderr).trim()))
        }
        Ok(out) => serde_json::from_slice::<serde_json::Value>(&out.stdout)
            .map_err(|e| format!("unreadable validator report: {e}")),
    };
    let json =
        or_skip(found, "the glTF validator (npm gltf-validator)", "DRESSFORM_REQUIRE_PEERS")?;
    let count = |k: &str| json["issues"][k].as_u64().unwrap_or(u64::MAX);
    Some(GltfReport { errors: count("numErrors"), warnings: count("numWarnings"), json })
}

/// Runs the `dressform` binary with `args`; returns (exit code, stdout, stderr).
pub fn dressform(args: &[&str]) -> (i32, String, String) {
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_dressform"))
        .args(args)
        .output()
        .expect("the dressform binary runs");
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// The files of an output directory, by name, without hidden entries; each must be a plain
/// file (not a link).
pub fn output_files(dir: &std::path::Path) -> Vec<(String, Vec<u8>)> {
    let mut files: Vec<(String, Vec<u8>)> = std::fs::read_dir(dir)
        .unwrap()
        .flatten()
        .map(|e| e.file_name().into_string().unwrap())
        .filter(|n| !n.starts_with('.'))
        .inspect(|n| {
            // Outputs are plain files a person can e-mail (issue 33), not links.
            let kind = std::fs::symlink_metadata(dir.join(n)).unwrap().file_type();
            assert!(kind.is_file(), "{n} in {} is not a plain file", dir.display());
        })
        .map(|n| (n.clone(), std::fs::read(dir.join(&n)).unwrap()))
        .collect();
    files.sort();
    files
}

use dressform::body::mesh::Mesh;
use glam::DVec3;
use std::collections::HashMap;

/// Closest point to `p` on triangle `abc` (Ericson, Real-Time Collision Detection, 5.1.5).
pub fn closest_on_triangle(p: DVec3, a: DVec3, b: DVec3, c: DVec3) -> DVec3 {
    let (ab, ac, ap) = (b - a, c - a, p - a);
    let (d1, d2) = (ab.dot(ap), ac.dot(ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return a;
    }
    let bp = p - b;
    let (d3, d4) = (ab.dot(bp), ac.dot(bp));
    if d3 >= 0.0 && d4 <= d3 {
        return b;
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return a + ab * (d1 / (d1 - d3));
    }
    let cp = p - c;
    let (d5, d6) = (ab.dot(cp), ac.dot(cp));
    if d6 >= 0.0 && d5 <= d6 {
        return c;
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return a + ac * (d2 / (d2 - d6));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
    }
    let denom = 1.0 / (va + vb + vc);
    a + ab * (vb * denom) + ac * (vc * denom)
}

/// Distances from points to a surface, with the triangles bucketed by height so that a query
/// only looks at triangles within `reach` mm of its height.
pub struct SurfaceDistance<'a> {
    mesh: &'a Mesh,
    reach: f64,
    bins: HashMap<i64, Vec<usize>>,
}

impl<'a> SurfaceDistance<'a> {
    pub fn new(mesh: &'a Mesh, reach: f64) -> Self {
        let mut bins: HashMap<i64, Vec<usize>> = HashMap::new();
        for t in 0..mesh.triangles.len() {
            let z = mesh.corners(t).map(|p| p.z);
            let lo = (z[0].min(z[1]).min(z[2]) / reach).floor() as i64;
            let hi = (z[0].max(z[1]).max(z[2]) / reach).floor() as i64;
            for b in lo..=hi {
                bins.entry(b).or_default().push(t);
            }
        }
        SurfaceDistance { mesh, reach, bins }
    }

    /// Distance from `p` to the surface, if the surface comes within `reach` of it.
    pub fn distance(&self, p: DVec3) -> Option<f64> {
        let b = (p.z / self.reach).floor() as i64;
        (b - 1..=b + 1)
            .filter_map(|k| self.bins.get(&k))
            .flatten()
            .map(|&t| {
                let [a, b, c] = self.mesh.corners(t);
                closest_on_triangle(p, a, b, c).distance(p)
            })
            .min_by(f64::total_cmp)
    }
}

/// The largest distance from any vertex of `mesh` to the nearest vertex of its mirror image
/// about the plane x = `axis`.
pub fn largest_mirror_gap(mesh: &Mesh, axis: f64) -> f64 {
    let cell = 1.0;
    let key = |p: DVec3| {
        ((p.x / cell).floor() as i64, (p.y / cell).floor() as i64, (p.z / cell).floor() as i64)
    };
    let mut grid: HashMap<(i64, i64, i64), Vec<DVec3>> = HashMap::new();
    for &p in &mesh.positions {
        grid.entry(key(p)).or_default().push(p);
    }
    mesh.positions
        .iter()
        .map(|&p| {
            let m = DVec3::new(2.0 * axis - p.x, p.y, p.z);
            let (i, j, k) = key(m);
            let mut best = f64::INFINITY;
            for di in -1..=1 {
                for dj in -1..=1 {
                    for dk in -1..=1 {
                        for q in grid.get(&(i + di, j + dj, k + dk)).into_iter().flatten() {
                            best = best.min(q.distance(m));
                        }
                    }
                }
            }
            best
        })
        .fold(0.0, f64::max)
}

/// A synthetic customer (the sim generator's default body) scanned with a typical scanner's
/// artifacts (noise, holes, metres, Y up, turned; `seed` picks them), written to
/// `dir/scan.ply`.
pub fn synthetic_scan(dir: &std::path::Path, seed: u64) -> PathBuf {
    use capture_sim::{Artifacts, BodyParams, capture, generate};
    let body = generate(&BodyParams::default()).expect("the default body generates");
    let raw = capture(&body, &Artifacts::typical_scanner(seed));
    let mesh =
        Mesh::new(raw.positions.iter().map(|&p| DVec3::from_array(p)).collect(), raw.triangles);
    let path = dir.join("scan.ply");
    std::fs::write(&path, dressform::body::scan::format::Format::Ply.encode(&mesh))
        .expect("writable");
    path
}

/// A generated customer's surface as a mesh (in the canonical frame, as the generator makes it).
pub fn mesh_of(body: &capture_sim::SyntheticBody) -> Mesh {
    surface_mesh(&body.surface)
}

/// A triangle surface of `capture-sim` (a generated body's, or a simulated scan) as a mesh.
pub fn surface_mesh(surface: &capture_sim::TriangleSurface) -> Mesh {
    Mesh::new(
        surface.positions.iter().map(|&p| DVec3::from_array(p)).collect(),
        surface.triangles.clone(),
    )
}

/// A number in `lo..hi` drawn from (`seed`, `k`) (splitmix64): reproducible, no state.
pub fn uniform(seed: u64, k: u64, lo: f64, hi: f64) -> f64 {
    let mut z = seed
        .wrapping_mul(0x9E37_79B9_7F4A_7C15)
        .wrapping_add(k.wrapping_mul(0xBF58_476D_1CE4_E5B9));
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^= z >> 31;
    lo + (hi - lo) * (z >> 11) as f64 / (1u64 << 53) as f64
}

/// How far in a scanner cuts a body: the soles (on its platform) and the crown (which it
/// does not see), in mm from the body's lowest and highest point.
#[derive(Clone, Copy)]
pub struct Cuts {
    pub soles_mm: f64,
    pub crown_mm: f64,
}

/// `mesh` as a scanner leaves it: the triangles within `cuts` of its lowest and highest point
/// (the soles, the crown) removed, and those within `radius_mm` of each of `holes`.
pub fn with_holes_and_cuts(mut mesh: Mesh, holes: &[DVec3], radius_mm: f64, cuts: Cuts) -> Mesh {
    let b = mesh.bounds().expect("a scan has vertices");
    let keep: Vec<bool> = (0..mesh.triangles.len())
        .map(|t| {
            let c = mesh.corners(t).iter().sum::<DVec3>() / 3.0;
            let cut = c.z < b.min.z + cuts.soles_mm || c.z > b.max.z - cuts.crown_mm;
            !cut && holes.iter().all(|h| h.distance(c) >= radius_mm)
        })
        .collect();
    mesh.retain_triangles(|t| keep[t]);
    mesh.drop_unused_vertices();
    mesh
}

/// A coarse scan (8 mm grid, not the default 4: a quarter of the triangles, so that many
/// scans run quickly) of synthetic customer `k` (1600 + 20 k mm tall), with a typical
/// scanner's artifacts, as PLY bytes in metres, Y up.
pub fn coarse_scan(k: u64) -> Vec<u8> {
    use capture_sim::{Artifacts, BodyParams, capture, generate};
    let height_mm = 1600.0 + 20.0 * k as f64;
    // The default body's legs (790 of 1700 mm), in proportion.
    let leg_length_mm = height_mm * 790.0 / 1700.0;
    let params = BodyParams { height_mm, leg_length_mm, resolution_mm: 8.0, ..Default::default() };
    let body = generate(&params).expect("the body generates");
    let raw = capture(&body, &Artifacts::typical_scanner(k));
    let mesh =
        Mesh::new(raw.positions.iter().map(|&p| DVec3::from_array(p)).collect(), raw.triangles);
    dressform::body::scan::format::Format::Ply.encode(&mesh)
}
