//! One test per class of bad input, through the `dressform` binary: a clear message naming the
//! file, exit status 2 for errors, a warning (and status 0) for problems that are repaired.

use crate::common;

use common::dressform;
use std::path::{Path, PathBuf};

/// A closed octahedron of human size (1.7 units tall), as OBJ text, plus `extra` lines.
fn octahedron_obj(extra: &str) -> String {
    format!(
        "v 0 0 0\nv 0.2 0.85 0\nv 0 0.85 0.1\nv -0.2 0.85 0\nv 0 0.85 -0.1\nv 0 1.7 0\n\
         f 1 3 2\nf 1 4 3\nf 1 5 4\nf 1 2 5\nf 6 2 3\nf 6 3 4\nf 6 4 5\nf 6 5 2\n{extra}"
    )
}

fn write(dir: &Path, name: &str, bytes: impl AsRef<[u8]>) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, bytes).unwrap();
    path
}

/// Runs `info` on `path`; asserts it fails with status 2 and a message naming the file that
/// contains `expected`.
fn assert_rejected(path: &Path, expected: &str) {
    let (code, _, stderr) = dressform(&["info", path.to_str().unwrap()]);
    assert_eq!(code, 2, "stderr: {stderr}");
    let name = path.file_name().unwrap().to_str().unwrap();
    assert!(stderr.contains(name), "message does not name the file: {stderr}");
    assert!(stderr.contains(expected), "expected '{expected}' in: {stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
}

/// Runs `info --json` on `path`; asserts success, a warning containing `expected`, and returns
/// the report.
fn assert_warned(path: &Path, expected: &str) -> serde_json::Value {
    let (code, stdout, stderr) = dressform(&["info", "--json", path.to_str().unwrap()]);
    assert_eq!(code, 0, "stderr: {stderr}");
    assert!(
        stderr.contains("warning") && stderr.contains(expected),
        "expected '{expected}' in: {stderr}"
    );
    serde_json::from_str(&stdout).unwrap()
}

#[test]
fn a_clean_body_gives_no_warning() {
    let dir = tempfile::tempdir().unwrap();
    let path = write(dir.path(), "ok.obj", octahedron_obj(""));
    let (code, stdout, stderr) = dressform(&["info", "--json", path.to_str().unwrap()]);
    assert_eq!(code, 0, "{stderr}");
    assert!(stderr.is_empty(), "{stderr}");
    let info: serde_json::Value = serde_json::from_str(&stdout).unwrap();
    assert_eq!(info["body"]["closed"], true);
    assert_eq!(info["frame"]["units"], "m");
    assert!((info["body"]["height_mm"].as_f64().unwrap() - 1700.0).abs() < 1e-9);
}

#[test]
fn empty_file() {
    let dir = tempfile::tempdir().unwrap();
    for name in ["empty.obj", "empty.ply", "empty.stl"] {
        assert_rejected(&write(dir.path(), name, ""), "empty");
    }
}

#[test]
fn missing_file_and_unknown_format() {
    let dir = tempfile::tempdir().unwrap();
    assert_rejected(&dir.path().join("absent.obj"), "cannot read");
    assert_rejected(&write(dir.path(), "scan.xyz", "1 2 3"), "unknown mesh format");
}

#[test]
fn truncated_binary_stl() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = dressform::scan::format::Format::Obj.read(octahedron_obj("").as_bytes()).unwrap();
    let full = dressform::scan::format::Format::Stl.encode(&mesh);
    assert_rejected(&write(dir.path(), "cut.stl", &full[..full.len() - 7]), "truncated");
    assert_rejected(&write(dir.path(), "tiny.stl", &full[..40]), "truncated");
}

#[test]
fn truncated_binary_ply() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = dressform::scan::format::Format::Obj.read(octahedron_obj("").as_bytes()).unwrap();
    let full = dressform::scan::format::Format::Ply.encode(&mesh);
    assert_rejected(&write(dir.path(), "cut.ply", &full[..full.len() - 5]), "truncated");
}

#[test]
fn malformed_text() {
    let dir = tempfile::tempdir().unwrap();
    assert_rejected(&write(dir.path(), "junk.ply", "ply\nformat nonsense\n"), "malformed");
    assert_rejected(&write(dir.path(), "junk.obj", "v 1 2 three\nf 1 2 3\n"), "malformed");
}

#[test]
fn nan_and_infinite_coordinates() {
    let dir = tempfile::tempdir().unwrap();
    let nan = octahedron_obj("").replacen("v 0 1.7 0", "v 0 NaN 0", 1);
    assert_rejected(&write(dir.path(), "nan.obj", nan), "vertex 5 has a non-finite coordinate");
    let inf = octahedron_obj("").replacen("v 0.2 0.85 0", "v inf 0.85 0", 1);
    assert_rejected(&write(dir.path(), "inf.obj", inf), "non-finite");
}

#[test]
fn face_index_out_of_range() {
    let dir = tempfile::tempdir().unwrap();
    assert_rejected(&write(dir.path(), "index.obj", octahedron_obj("f 1 2 99\n")), "out of bounds");
    let ply = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n\
               element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n";
    assert_rejected(
        &write(dir.path(), "index.ply", ply),
        "face 0 refers to vertex 7, but there are only 3 vertices",
    );
    let negative = ply.replace("3 0 1 7", "3 0 -1 2");
    assert_rejected(&write(dir.path(), "negative.ply", negative), "refers to vertex -1");
}

#[test]
fn no_faces() {
    let dir = tempfile::tempdir().unwrap();
    assert_rejected(&write(dir.path(), "points.obj", "v 0 0 0\nv 1 1 1\n"), "no faces");
}

#[test]
fn degenerate_faces_are_dropped() {
    let dir = tempfile::tempdir().unwrap();
    let path = write(dir.path(), "degenerate.obj", octahedron_obj("f 1 1 2\nf 1 6 6\n"));
    let info = assert_warned(&path, "dropped 2 degenerate");
    assert_eq!(info["cleaning"]["degenerate_triangles"], 2);
    assert_eq!(info["body"]["closed"], true);
}

#[test]
fn non_manifold_edges_are_reported() {
    let dir = tempfile::tempdir().unwrap();
    // A fin: a third triangle on the edge 1-2, sharing it with two faces of the body.
    let path = write(dir.path(), "fin.obj", octahedron_obj("v 0.5 -0.2 0.5\nf 1 2 7\n"));
    let info = assert_warned(&path, "not manifold");
    assert_eq!(info["body"]["non_manifold_edges"], 1);
    assert_eq!(info["body"]["manifold"], false);
}

#[test]
fn several_components_keep_the_body_and_say_what_was_dropped() {
    let dir = tempfile::tempdir().unwrap();
    let floor = "v -0.3 -0.01 -0.3\nv 0.3 -0.01 -0.3\nv 0.3 -0.01 0.3\nf 7 8 9\n";
    let island = "v 0.5 1 0.5\nv 0.51 1 0.5\nv 0.5 1.01 0.5\nf 10 11 12\n";
    let path = write(dir.path(), "islands.obj", octahedron_obj(&format!("{floor}{island}")));
    let info = assert_warned(&path, "dropped 2 others");
    assert_eq!(info["components"]["count"], 3);
    assert_eq!(info["components"]["dropped"].as_array().unwrap().len(), 2);
    assert!(
        (info["body"]["height_mm"].as_f64().unwrap() - 1700.0).abs() < 1e-9,
        "the floor patch is gone"
    );
}

#[test]
fn holes_are_counted() {
    let dir = tempfile::tempdir().unwrap();
    let text = octahedron_obj("").replace("f 6 2 3\n", "").replace("f 1 5 4\n", "");
    let info = assert_warned(&write(dir.path(), "holes.obj", text), "2 holes");
    assert_eq!(info["body"]["holes"], 2);
    assert_eq!(info["body"]["closed"], false);
}

#[test]
fn height_of_no_known_unit_asks_for_units() {
    let dir = tempfile::tempdir().unwrap();
    let tiny = octahedron_obj("").replace("1.7", "0.017").replace("0.85", "0.0085");
    assert_rejected(&write(dir.path(), "tiny.obj", tiny), "pass --units");
}

#[test]
fn bad_flags_are_usage_errors() {
    let (code, _, stderr) = dressform(&["info", "x.obj", "--up", "sideways"]);
    assert_eq!(code, 2);
    assert!(stderr.contains("not an axis"), "{stderr}");
    for (command, flag) in [("slice", "--heights"), ("measure", "--at")] {
        let (code, _, stderr) = dressform(&[command, "x.obj", flag, "900,NaN"]);
        assert_eq!(code, 2, "{stderr}");
        assert!(stderr.contains(&format!("{flag}: NaN is not a height")), "{stderr}");
    }
}

/// Output streams that fail: a reader that closed the pipe ends the output quietly; a full
/// device for the output is an error (status 1); a failing standard error loses the messages.
/// Never a panic (status 101).
#[test]
fn failing_output_streams() {
    use std::process::{Command, Stdio};
    let dir = tempfile::tempdir().unwrap();
    let path = write(dir.path(), "ok.obj", octahedron_obj(""));
    let warned = write(dir.path(), "degenerate.obj", octahedron_obj("f 1 1 2\n"));
    let full = || std::fs::OpenOptions::new().write(true).open("/dev/full").unwrap();
    let closed_pipe = || {
        let (reader, writer) = std::io::pipe().unwrap();
        drop(reader);
        writer
    };
    let run = |args: &[&str], stdout: Stdio, stderr: Stdio| {
        let out = Command::new(env!("CARGO_BIN_EXE_dressform"))
            .args(args)
            .stdout(stdout)
            .stderr(stderr)
            .output()
            .unwrap();
        (out.status.code(), String::from_utf8_lossy(&out.stderr).into_owned())
    };
    let info = ["info", path.to_str().unwrap()];
    let (code, stderr) = run(&info, closed_pipe().into(), Stdio::piped());
    assert_eq!(code, Some(0), "{stderr}");
    assert!(stderr.is_empty(), "{stderr}");

    let (code, stderr) = run(&info, full().into(), Stdio::piped());
    assert_eq!(code, Some(1), "{stderr}");
    assert!(stderr.contains("cannot write the output"), "{stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");

    // Warnings and errors on a standard error that cannot take them.
    let warn = ["info", warned.to_str().unwrap()];
    assert_eq!(run(&warn, Stdio::null(), closed_pipe().into()).0, Some(0));
    assert_eq!(run(&warn, Stdio::null(), full().into()).0, Some(0));
    assert_eq!(run(&info, full().into(), full().into()).0, Some(1));
    let missing = ["info", "no-such-scan.ply"];
    assert_eq!(run(&missing, Stdio::null(), closed_pipe().into()).0, Some(2));
}

#[test]
fn face_counts_beyond_the_file_are_truncation() {
    let dir = tempfile::tempdir().unwrap();
    let mut ply = b"ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\n\
                    property float y\nproperty float z\nelement face 4611686018427387904\n\
                    property list uchar int vertex_indices\nend_header\n"
        .to_vec();
    for p in [[0f32, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.7, 0.0]] {
        p.iter().for_each(|c| ply.extend(c.to_le_bytes()));
    }
    ply.push(4); // a quad, so the faces are read one by one
    [0i32, 1, 2, 0].iter().for_each(|i| ply.extend(i.to_le_bytes()));
    assert_rejected(&write(dir.path(), "count.ply", ply), "truncated");
}
