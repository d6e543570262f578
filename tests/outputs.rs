//! What `symmetrize` writes: meshes for CAD tools (glb validated by the Khronos validator), the
//! output set replaced as a whole, and the same bytes on every run, whatever the thread count.

use crate::common;

use common::{dressform, output_files, synthetic_scan};
use dressform::body::scan::format::{Format, comment_value};
use glam::DVec3;

fn symmetrize(args: &[&str]) -> (i32, String, String) {
    let mut all = vec!["symmetrize"];
    all.extend(args);
    dressform(&all)
}

#[test]
fn glb_for_cad_and_the_set_replaced_as_a_whole() {
    let tmp = tempfile::tempdir().unwrap();
    let scan = synthetic_scan(tmp.path(), 3);
    let (scan, out) = (scan.to_str().unwrap(), tmp.path().join("out"));
    let out_s = out.to_str().unwrap();
    let (code, _, stderr) = symmetrize(&[scan, "-o", out_s]);
    assert_eq!(code, 0, "{stderr}");
    let obj = dressform::body::scan::read_mesh_file(&out.join("mannequin.obj")).unwrap().0;
    assert_eq!(comment_value(&obj.comments, "units"), Some("mm"));

    let args = [scan, "-o", out_s, "--format", "glb", "--units", "m", "--up", "y"];
    let (code, _, stderr) = symmetrize(&args);
    assert_eq!(code, 0, "{stderr}");
    let names: Vec<String> = output_files(&out).into_iter().map(|(n, _)| n).collect();
    assert_eq!(
        names,
        [
            "mannequin.glb",
            "measurements.json",
            "preview.png",
            "profiles.json",
            "report.html",
            "sections.svg"
        ],
        "no mannequin.obj left"
    );
    let glb = dressform::body::scan::read_mesh_file(&out.join("mannequin.glb")).unwrap().0;
    assert_eq!(comment_value(&glb.comments, "up"), Some("+y"));
    // The same mannequin: metres and Y up (x, y, z) -> (x, z, -y) in mm, Z up; f32 in the glb.
    assert_eq!(glb.mesh.triangles, obj.mesh.triangles);
    for (g, o) in glb.mesh.positions.iter().zip(&obj.mesh.positions) {
        let back = DVec3::new(g.x, -g.z, g.y) * 1000.0;
        assert!((back - *o).abs().max_element() < 1e-3, "{back} vs {o}");
    }
    if let Some(report) = common::validate_gltf(&out.join("mannequin.glb")) {
        assert_eq!(report.errors, 0, "{:#}", report.json);
    }

    // Flags glb cannot honour, and flags that contradict each other.
    let (code, _, stderr) = symmetrize(&[scan, "-o", out_s, "--format", "glb", "--units", "mm"]);
    assert_eq!(code, 2, "{stderr}");
    assert!(stderr.contains("glb files are in metres with Y up"), "{stderr}");
    let (code, _, stderr) = symmetrize(&[scan, "-o", out_s, "--scan-frame", "--up", "y"]);
    assert_eq!(code, 2, "{stderr}");
    // A failed command leaves the set as it was.
    assert_eq!(output_files(&out).len(), 6);
    assert!(out.join("mannequin.glb").is_file());

    // PLY in centimetres, Z up: read back with its header.
    let (code, _, stderr) = symmetrize(&[scan, "-o", out_s, "--format", "ply", "--units", "cm"]);
    assert_eq!(code, 0, "{stderr}");
    let ply = dressform::body::scan::read_mesh_file(&out.join("mannequin.ply")).unwrap();
    assert_eq!(ply.1, Format::Ply);
    assert_eq!(comment_value(&ply.0.comments, "units"), Some("cm"));
    assert!(!out.join("mannequin.glb").exists());
}

/// Issue 16, case 6: two runs on the same input give the same bytes, with 1, 2 or 3 threads
/// (rayon splits its parallel sums differently for each; the reductions are in fixed order).
#[test]
fn the_same_input_gives_the_same_bytes() {
    let tmp = tempfile::tempdir().unwrap();
    let scan = synthetic_scan(tmp.path(), 5);
    let runs: Vec<Vec<(String, Vec<u8>)>> = ["1", "2", "3"]
        .iter()
        .map(|threads| {
            let out = tmp.path().join(format!("out-{threads}"));
            let status = std::process::Command::new(env!("CARGO_BIN_EXE_dressform"))
                .args(["symmetrize", scan.to_str().unwrap(), "-o", out.to_str().unwrap()])
                .env("RAYON_NUM_THREADS", threads)
                .output()
                .unwrap();
            assert!(status.status.success(), "{}", String::from_utf8_lossy(&status.stderr));
            output_files(&out)
        })
        .collect();
    assert_eq!(runs[0].len(), 6, "mannequin, profiles, measurements, the two pictures, report");
    for run in &runs[1..] {
        for ((name, a), (_, b)) in runs[0].iter().zip(run) {
            assert!(a == b, "{name} differs between runs");
        }
    }
}

/// Issue 16, case 5: a disk that fills up while the set is written (here: a file-size limit,
/// which fails writes the same way) leaves the older set whole, with a clear message and exit
/// status 1; the next run that can write replaces it.
#[test]
fn a_full_disk_leaves_the_older_set_whole() {
    use std::os::unix::process::CommandExt;
    let tmp = tempfile::tempdir().unwrap();
    let scan = synthetic_scan(tmp.path(), 7);
    let out = tmp.path().join("out");
    let args = ["symmetrize", scan.to_str().unwrap(), "-o", out.to_str().unwrap()];
    let (code, _, stderr) = dressform(&[&args[..], &["--torso-layers", "60"]].concat());
    assert_eq!(code, 0, "{stderr}");
    let older = output_files(&out);

    let mut limited = std::process::Command::new(env!("CARGO_BIN_EXE_dressform"));
    limited.args(args);
    // SAFETY: only async-signal-safe calls between fork and exec.
    unsafe {
        limited.pre_exec(|| {
            // Files may grow to 64 KiB (the mannequin needs megabytes); a write beyond fails
            // with EFBIG instead of stopping the process.
            let limit = libc::rlimit { rlim_cur: 64 << 10, rlim_max: libc::RLIM_INFINITY };
            libc::signal(libc::SIGXFSZ, libc::SIG_IGN);
            if libc::setrlimit(libc::RLIMIT_FSIZE, &limit) != 0 {
                return Err(std::io::Error::last_os_error());
            }
            Ok(())
        });
    }
    let run = limited.output().unwrap();
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert_eq!(run.status.code(), Some(1), "{stderr}");
    let errors: Vec<&str> = stderr.lines().filter(|l| l.starts_with("error")).collect();
    assert_eq!(errors.len(), 1, "{stderr}");
    assert!(errors[0].contains("out/mannequin.obj: cannot write: File too large"), "{stderr}");
    assert!(output_files(&out) == older, "the older set changed");

    let (code, _, stderr) = dressform(&args);
    assert_eq!(code, 0, "{stderr}");
    assert!(output_files(&out) != older);
    let beside: Vec<_> = std::fs::read_dir(tmp.path())
        .unwrap()
        .flatten()
        .filter(|e| e.file_name().to_string_lossy().starts_with(".out.dressform-"))
        .collect();
    assert!(beside.is_empty(), "the failed run's partial set is gone: {beside:?}");
}
