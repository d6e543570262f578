//! MakeHuman bodies scanned as a body scanner would: posed with MakeHuman's own 163-bone rig,
//! re-meshed by marching cubes (`tests/scripts/remesh.py`: no vertex of the template
//! survives), noise along every axis, holes where a scanner sees nothing (under the arms, below
//! the crotch), the soles and crown cut. Shared by `pose_symmetry_cases` and
//! `mannequin_population`.

use crate::common::{self, Cuts};
use dressform::body::mesh::Mesh;
use dressform::pose::makehuman::{MakeHuman, Pose};
use dressform::shape::measure::central_loops;
use glam::DVec3;
use rand::rngs::ChaCha8Rng;
use rand_distr::{Distribution, Normal};
use std::path::{Path, PathBuf};

/// The holes' radius (mm) at the armpits and the crotch.
pub const HOLE_RADIUS_MM: f64 = 30.0;

/// The pose of `bones` (MakeHuman bone, rotation vector) from the rest pose.
pub fn pose_of(bones: &[(String, DVec3)]) -> Pose {
    bones.iter().fold(Pose::rest(), |p, (b, t)| p.rotate(b, *t))
}

/// The skin of `body` (MakeHuman's vertices, shaped) posed by `bones`.
pub fn posed(mh: &MakeHuman, body: &[DVec3], bones: &[(String, DVec3)]) -> Mesh {
    mh.base.skin(&mh.pose(body, &pose_of(bones)).unwrap())
}

/// The scan's vertices moved by noise of `noise_mm` (standard deviation per axis), with holes
/// at `holes` and the soles and crown cut as `cuts` says.
/// The soles end on the scanner's platform: every vertex left below `floor` + `cuts.soles_mm`
/// (`floor` the body's lowest point before noise) is lifted onto that plane, so that the
/// scan's floor is the platform's, not wherever the noise and the mesh's triangles put its
/// lowest vertex (which moved the loaded scan 0-3 mm up or down, and its girths with it).
pub fn scanned(
    mesh: &Mesh,
    floor: f64,
    holes: &[DVec3],
    cuts: Cuts,
    noise_mm: f64,
    rng: &mut ChaCha8Rng,
) -> Mesh {
    let noise = Normal::new(0.0, noise_mm).unwrap();
    let mut mesh = mesh.clone();
    for p in &mut mesh.positions {
        *p += DVec3::new(noise.sample(rng), noise.sample(rng), noise.sample(rng));
    }
    let centres: Vec<DVec3> = holes
        .iter()
        .map(|h| {
            *mesh.positions.iter().min_by(|a, c| a.distance(*h).total_cmp(&c.distance(*h))).unwrap()
        })
        .collect();
    let platform = floor + cuts.soles_mm;
    common::with_holes_and_cuts(mesh, &centres, HOLE_RADIUS_MM, cuts)
        .map_positions(|p| DVec3::new(p.x, p.y, p.z.max(platform)))
}

/// Where a scanner leaves holes on a MakeHuman body whose bones have `heads`: under each arm,
/// on the side of the chest (the arm hides it), and below the crotch.
pub fn hole_sites(mh: &MakeHuman, heads: &[DVec3]) -> [DVec3; 3] {
    let joint = |name: &str| heads[mh.rig.bone(name).unwrap()];
    let under_arm = |side: &str| {
        let (s, c) = (joint(&format!("upperarm01{side}")), joint(&format!("clavicle{side}")));
        DVec3::new(s.x * 0.8, s.y, s.z - (s.x - c.x).abs())
    };
    let crotch = (joint("upperleg01.L") + joint("upperleg01.R")) / 2.0 - DVec3::Z * 100.0;
    [under_arm(".L"), under_arm(".R"), crotch]
}

pub fn write_obj(mesh: &Mesh, path: &Path) {
    std::fs::write(path, dressform::body::scan::format::Format::Obj.encode(mesh)).unwrap();
}

/// A scan file read as the commands read it: into the canonical frame, then Taubin-smoothed
/// (`--smooth`'s default).
pub fn load(path: &Path) -> dressform::body::scan::Scan {
    let mut scan = dressform::body::scan::load(path, &Default::default()).unwrap();
    scan.body.taubin_smooth(dressform::body::mesh::smooth::DEFAULT_PASSES);
    scan
}

/// The torso's tape girths of `body` at `heights`, its symmetry plane at x = `axis`.
pub fn girths(body: &Mesh, axis: f64, heights: &[f64]) -> Vec<f64> {
    central_loops(body, axis, heights)
        .into_iter()
        .map(|c| c.map_or(f64::NAN, |c| c.tape_girth()))
        .collect()
}

/// python3, when it has what `remesh.py` imports; else `None` with a message (a failure with
/// `DRESSFORM_REQUIRE_PEERS`, as in CI).
pub fn remesher() -> Option<String> {
    let found = std::process::Command::new("python3")
        .args(["-c", "import trimesh, scipy, skimage"])
        .output()
        .map_err(|e| format!("python3: {e}"))
        .and_then(|probe| {
            if probe.status.success() {
                Ok("python3".to_string())
            } else {
                let stderr = String::from_utf8_lossy(&probe.stderr);
                Err(stderr.lines().last().unwrap_or_default().to_string())
            }
        });
    common::or_skip(found, "python3 with trimesh, scipy, scikit-image", "DRESSFORM_REQUIRE_PEERS")
}

/// Re-meshes every `(source OBJ, target PLY)` pair at `pitch_mm` in one run of `remesh.py`.
pub fn remesh(python: &str, pitch_mm: f64, pairs: &[(PathBuf, PathBuf)]) {
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/scripts/remesh.py");
    let mut args = vec![pitch_mm.to_string()];
    for (source, target) in pairs {
        args.extend([source.display().to_string(), target.display().to_string()]);
    }
    let status = std::process::Command::new(python).arg(script).args(&args).status().unwrap();
    assert!(status.success(), "remesh.py failed");
}
