//! One test per class of bad input, through the `dressform` binary: a clear message naming the
//! file, exit status 2 for errors, a warning (and status 0) for problems that are repaired.
//! The cases of the reliability campaign (issue 16) each have a test here, their files built in
//! the test.

use crate::common;

use common::dressform;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// Longer than any of these runs takes on a loaded machine (a few seconds at most), far shorter
/// than the hangs and quadratic runs they guard against (minutes to forever).
const HANG: Duration = Duration::from_secs(120);

/// Runs `dressform args`, killing it if it runs longer than [`HANG`]; (exit code, stdout,
/// stderr).
fn dressform_within(args: &[&str]) -> (i32, String, String) {
    use std::process::{Command, Stdio};
    let mut child = Command::new(env!("CARGO_BIN_EXE_dressform"))
        .args(args)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let start = Instant::now();
    while child.try_wait().unwrap().is_none() {
        if start.elapsed() > HANG {
            child.kill().unwrap();
            panic!("dressform {args:?} ran longer than {HANG:?}");
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    let out = child.wait_with_output().unwrap();
    let text = |b: Vec<u8>| String::from_utf8_lossy(&b).into_owned();
    (out.status.code().unwrap_or(-1), text(out.stdout), text(out.stderr))
}

/// Asserts that `stderr` is one error line of bounded length, without control characters or
/// parser internals.
fn assert_one_clean_line(stderr: &str) {
    let lines: Vec<&str> = stderr.lines().collect();
    assert_eq!(lines.len(), 1, "{stderr}");
    let bound = dressform::messages::MAX_LINE + 60;
    assert!(lines[0].chars().count() <= bound, "{} characters: {stderr}", lines[0].len());
    assert!(!lines[0].chars().any(char::is_control), "{stderr:?}");
    for internal in ["ParseError", "LineCol", "ExpectedSet", "Error {", "location"] {
        assert!(!stderr.contains(internal), "{stderr}");
    }
}

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

/// Runs `info` on `path`; asserts it fails with status 2 and one clean line naming the file
/// that contains `expected`.
fn assert_rejected(path: &Path, expected: &str) {
    let (code, _, stderr) = dressform_within(&["info", path.to_str().unwrap()]);
    assert_eq!(code, 2, "stderr: {stderr}");
    let name = path.file_name().unwrap().to_str().unwrap();
    assert!(stderr.contains(name), "message does not name the file: {stderr}");
    assert!(stderr.contains(expected), "expected '{expected}' in: {stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
    assert_one_clean_line(&stderr);
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
    let mesh =
        dressform::body::scan::format::Format::Obj.read(octahedron_obj("").as_bytes()).unwrap();
    let full = dressform::body::scan::format::Format::Stl.encode(&mesh);
    assert_rejected(&write(dir.path(), "cut.stl", &full[..full.len() - 7]), "truncated");
    assert_rejected(&write(dir.path(), "tiny.stl", &full[..40]), "truncated");
}

#[test]
fn truncated_binary_ply() {
    let dir = tempfile::tempdir().unwrap();
    let mesh =
        dressform::body::scan::format::Format::Obj.read(octahedron_obj("").as_bytes()).unwrap();
    let full = dressform::body::scan::format::Format::Ply.encode(&mesh);
    assert_rejected(&write(dir.path(), "cut.ply", &full[..full.len() - 5]), "truncated");
}

#[test]
fn malformed_text() {
    let dir = tempfile::tempdir().unwrap();
    assert_rejected(
        &write(dir.path(), "junk.ply", "ply\nformat nonsense\n"),
        "line 2: format 'nonsense' is not ascii, binary_little_endian or binary_big_endian",
    );
    assert_rejected(
        &write(dir.path(), "junk.obj", "v 1 2 three\nf 1 2 3\n"),
        "line 1: 'three' is not a number",
    );
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
    assert_rejected(
        &write(dir.path(), "index.obj", octahedron_obj("f 1 2 99\n")),
        "line 15: the face refers to vertex 99, but the file has 6",
    );
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
    // The legs' options, shared by every command that builds a mannequin: clap's error, naming
    // the flag and the values it takes.
    for command in
        [&["symmetrize", "x.obj"][..], &["reconstruct", "x.obj"], &["run", "x.obj"], &["demo"]]
    {
        for (flag, value, values) in
            [("--legs", "bent", "straight, as-scanned"), ("--stop-at", "knee", "thigh")]
        {
            let (code, _, stderr) = dressform(&[command, &[flag, value]].concat());
            assert_eq!(code, 2, "{command:?} {flag}: {stderr}");
            let named = format!("invalid value '{value}' for '{flag}");
            assert!(stderr.contains(&named) && stderr.contains(values), "{stderr}");
        }
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

/// Issue 16, case 1: a count that the rest of the file cannot hold is refused (it used to
/// abort the process allocating 8 GB), and so is an element with no properties and a huge
/// count (it used to loop forever). The face element's second list sends the file down the
/// general path, as in the campaign.
#[test]
fn ply_counts_the_file_cannot_hold() {
    let dir = tempfile::tempdir().unwrap();
    let faces =
        "element face 1\nproperty list uchar int vertex_indices\nproperty list uchar int extra\n";
    let cases = [
        (
            "element vertex 4000000000\n",
            "element 'vertex' declares 4000000000 items but has no properties",
        ),
        (
            "element vertex 4000000000\nproperty float x\nproperty float y\nproperty float z\n",
            "truncated: element 'vertex' declares 4000000000 items (at least 48000000000 bytes)",
        ),
        (
            "element vertex 3\nproperty float x\nproperty float y\nproperty float z\n\
             element junk 18446744073709551615\n",
            "element 'junk' declares 18446744073709551615 items but has no properties",
        ),
    ];
    for (k, (elements, expected)) in cases.into_iter().enumerate() {
        let header = format!("ply\nformat binary_little_endian 1.0\n{elements}{faces}end_header\n");
        let mut bytes = header.into_bytes();
        bytes.resize(bytes.len() + 64, 0);
        assert_rejected(&write(dir.path(), &format!("count{k}.ply"), bytes), expected);
    }
}

/// Issue 16, case 2: topology around a vertex with a huge fan, and a huge polygon, in linear
/// time: a 400,000-triangle PLY cone round its apex and an OBJ polygon of 500,000 corners (the
/// pairwise comparison took 9.8 s for 80,000 and would take minutes here; see the `readers`
/// bench for the timings).
#[test]
fn huge_fans_and_polygons_are_read_in_linear_time() {
    let dir = tempfile::tempdir().unwrap();
    let n = 400_000u32;
    let rim = |i: u32, n: u32| {
        let a = std::f64::consts::TAU * f64::from(i) / f64::from(n);
        [0.3 * a.cos(), 0.3 * a.sin(), 0.0]
    };
    let mut ply = format!(
        "ply\nformat binary_little_endian 1.0\nelement vertex {}\nproperty float x\nproperty float y\n\
         property float z\nelement face {n}\nproperty list uchar int vertex_indices\nend_header\n",
        n + 1
    )
    .into_bytes();
    for p in std::iter::once([0.0, 0.0, 1.7]).chain((0..n).map(|i| rim(i, n))) {
        p.iter().for_each(|&c| ply.extend((c as f32).to_le_bytes()));
    }
    for i in 0..n {
        ply.push(3);
        [0, 1 + i, 1 + (i + 1) % n].iter().for_each(|&v| ply.extend((v as i32).to_le_bytes()));
    }
    let m = 500_000u32;
    let mut obj = String::from("v 0 0 1.7\n");
    for i in 0..m {
        let [x, y, z] = rim(i, m);
        obj.push_str(&format!("v {x:.7} {y:.7} {z}\n"));
    }
    obj.push('f');
    (1..=m + 1).for_each(|k| obj.push_str(&format!(" {k}")));
    obj.push('\n');
    for (name, bytes, triangles) in
        [("cone.ply", ply, n as u64), ("polygon.obj", obj.into_bytes(), m as u64 - 1)]
    {
        let path = write(dir.path(), name, bytes);
        let (code, stdout, stderr) = dressform_within(&["info", "--json", path.to_str().unwrap()]);
        assert_eq!(code, 0, "{name}: {stderr}");
        let info: serde_json::Value = serde_json::from_str(&stdout).unwrap();
        assert_eq!(info["triangles"], triangles, "{name}");
        assert_eq!(info["body"]["manifold"], true, "{name}");
        assert_eq!(info["body"]["holes"], 1, "{name}: the open rim");
    }
}

/// Issue 16, case 3: an ASCII PLY with CR-only line endings reads like any other; messages
/// are one clean line; files that are not meshes are named.
#[test]
fn line_endings_and_messages() {
    let dir = tempfile::tempdir().unwrap();
    let lf = octahedron_obj("");
    let mesh = dressform::body::scan::format::Format::Obj.read(lf.as_bytes()).unwrap();
    let mut ply = format!(
        "ply\nformat ascii 1.0\nelement vertex {}\nproperty double x\nproperty double y\n\
         property double z\nelement face {}\nproperty list uchar int vertex_indices\nend_header\n",
        mesh.positions.len(),
        mesh.triangles.len()
    );
    mesh.positions.iter().for_each(|p| ply.push_str(&format!("{} {} {}\n", p.x, p.y, p.z)));
    mesh.triangles.iter().for_each(|t| ply.push_str(&format!("3 {} {} {}\n", t[0], t[1], t[2])));
    let reports: Vec<serde_json::Value> = ["\n", "\r", "\r\n"]
        .iter()
        .map(|eol| {
            let path = write(dir.path(), "eol.ply", ply.replace('\n', eol));
            let (code, stdout, stderr) = dressform(&["info", "--json", path.to_str().unwrap()]);
            assert_eq!(code, 0, "{eol:?}: {stderr}");
            serde_json::from_str(&stdout).unwrap()
        })
        .collect();
    assert!(reports.iter().all(|r| r["body"] == reports[0]["body"]), "{reports:?}");
    // A CR-only file with a mistake: one line, not the whole file.
    let bad = ply.replace("3 0 2 1", "3 0 2 x").replace('\n', "\r");
    assert_rejected(&write(dir.path(), "cr.ply", bad), "line 16: 'x' is not an integer");

    let utf16: Vec<u8> = lf.encode_utf16().flat_map(u16::to_le_bytes).collect();
    let png = b"\x89PNG\r\n\x1a\n\0\0\0\rIHDR".to_vec();
    for (name, bytes, expected) in [
        (
            "packed.obj",
            b"\x1f\x8b\x08\x00\x00\x00".to_vec(),
            "this is a gzip file; unpack it first",
        ),
        ("packed.ply", b"PK\x03\x04\x14\x00".to_vec(), "this is a zip archive; unpack it first"),
        ("wide.obj", utf16, "this is UTF-16 text; save it as UTF-8 or ASCII"),
        ("photo.stl", png, "this is a PNG image"),
        (
            "other.obj",
            b"ply\nformat ascii 1.0\n".to_vec(),
            "in PLY format, not OBJ; rename it to .ply",
        ),
    ] {
        assert_rejected(&write(dir.path(), name, bytes), expected);
    }
    // Numbers in a sensible precision, control characters escaped, long text cut.
    let huge: String = octahedron_obj("")
        .lines()
        .map(|l| match l.strip_prefix("v ") {
            Some(xyz) => {
                let scaled: Vec<String> = xyz
                    .split(' ')
                    .map(|c| (c.parse::<f64>().unwrap() * 1e60).to_string())
                    .collect();
                format!("v {}\n", scaled.join(" "))
            }
            None => format!("{l}\n"),
        })
        .collect();
    assert_rejected(&write(dir.path(), "huge.obj", huge), "the body is 1.7e60 units tall");
    let nan = octahedron_obj("").replace("v 0 1.7 0", "v 1e300 NaN 0");
    assert_rejected(&write(dir.path(), "nan.obj", nan), "non-finite coordinate (1e300, NaN, 0)");
    let escape = format!("v 0 0 0\nv 1 0 0\nv 0 1 \x1b[31m{}\nf 1 2 3\n", "9".repeat(5000));
    assert_rejected(&write(dir.path(), "escape.obj", escape), "'\\u{1b}[31m9999");
}

/// Issue 16, case 3 (set-points): 100,000 unknown actuator ids make one short line, and ids
/// with terminal escapes are shown escaped.
#[test]
fn setpoint_messages_are_bounded_and_escaped() {
    let dir = tempfile::tempdir().unwrap();
    let mut positions: serde_json::Map<String, serde_json::Value> =
        (0..100_000).map(|i| (format!("ghost-{i:06}"), 1.0.into())).collect();
    positions.insert("\u{1b}[2J\u{1b}]0;owned\u{7}".into(), 1.0.into());
    let file = serde_json::json!({
        "format": "dressform-setpoints/1", "form": "reference", "positions_mm": positions,
    });
    let path = write(dir.path(), "ghosts.json", file.to_string());
    let (code, _, stderr) = dressform_within(&["drive", path.to_str().unwrap(), "--sim"]);
    assert_eq!(code, 2, "{stderr}");
    assert_one_clean_line(&stderr);
    assert!(stderr.contains("100001 problems") && stderr.contains("\\u{1b}[2J"), "{stderr}");
}

/// Issue 16, case 4: only regular files (or links to them) are read: a FIFO with no writer, a
/// link to an endless device and a directory are refused at once.
#[test]
fn special_files_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let fifo = dir.path().join("pipe.obj");
    let c_path = std::ffi::CString::new(fifo.to_str().unwrap()).unwrap();
    // SAFETY: a valid NUL-terminated path; mkfifo only creates a file.
    assert_eq!(unsafe { libc::mkfifo(c_path.as_ptr(), 0o600) }, 0);
    assert_rejected(&fifo, "pipe.obj: a FIFO (named pipe), not a regular file");
    let random = dir.path().join("random.stl");
    std::os::unix::fs::symlink("/dev/urandom", &random).unwrap();
    assert_rejected(&random, "random.stl: a device, not a regular file");
    let folder = dir.path().join("folder.ply");
    std::fs::create_dir(&folder).unwrap();
    assert_rejected(&folder, "folder.ply: a directory, not a regular file");
    // A link to a regular file is fine.
    let target = write(dir.path(), "real.obj", octahedron_obj(""));
    let link = dir.path().join("link.obj");
    std::os::unix::fs::symlink(&target, &link).unwrap();
    assert_eq!(dressform(&["info", link.to_str().unwrap()]).0, 0);
}

/// The reference form's rings, each with `girth` as the mannequin's: a set-point file that
/// moves nothing.
fn girths_only(girth: f64) -> String {
    let form = form_description::reference();
    let girths: serde_json::Map<String, serde_json::Value> =
        form.rings.iter().map(|r| (r.name.clone(), girth.into())).collect();
    serde_json::json!({
        "format": "dressform-setpoints/1", "form": "reference", "positions_mm": {},
        "target_girths_mm": girths,
    })
    .to_string()
}

/// Issue 29: numbers such as 1e308 in set-points, profiles and forms were printed with 309
/// digits and the reason cut off; they are shown short, the whole reason on the line.
#[test]
fn huge_numbers_in_files_are_shown_short() {
    let dir = tempfile::tempdir().unwrap();
    // Set-points.
    let file = write(dir.path(), "setpoints.json", girths_only(-1e308));
    let (code, _, stderr) = dressform_within(&["drive", file.to_str().unwrap(), "--sim"]);
    assert_eq!(code, 2, "{stderr}");
    assert_one_clean_line(&stderr);
    assert!(
        stderr.contains(": -1e308 is not a girth in mm (above 0, at most 31415.9)"),
        "{stderr}"
    );
    assert!(!stderr.contains("more characters"), "{stderr}");
    // Profiles.
    let profiles = serde_json::json!({
        "format": "dressform-profiles/1", "frame": "canonical", "axis_x": 1e308, "rays": 360,
        "preserve": "tape",
        "levels": { "chest_mm": 1224.0, "waist_mm": 1049.0, "hip_mm": 868.0 },
        "landmarks": {
            "height_mm": 1700.0, "crotch_mm": 789.0, "ankle_mm": 112.0,
            "left_armpit_mm": 1275.0, "right_armpit_mm": 1261.0, "neck_mm": 1467.0,
            "centre_x_mm": -1.3,
            "left_armhole": { "armpit_mm": [162.0, 2.0, 1275.0],
                "shoulder_point_mm": [183.0, 19.0, 1392.0], "normal": [0.98, 0.0, -0.18] },
            "right_armhole": { "armpit_mm": [-172.0, 34.0, 1261.0],
                "shoulder_point_mm": [-191.0, 23.0, 1387.0], "normal": [-0.99, 0.0, -0.15] },
        },
        "layers": [],
    });
    let file = write(dir.path(), "profiles.json", profiles.to_string());
    let out = dir.path().join("out.json");
    let (code, _, stderr) =
        dressform_within(&["setpoints", file.to_str().unwrap(), "-o", out.to_str().unwrap()]);
    assert_eq!(code, 2, "{stderr}");
    assert_one_clean_line(&stderr);
    assert!(stderr.contains("axis_x: 1e308 is not within ±5000 mm"), "{stderr}");
    assert!(!stderr.contains("more characters"), "{stderr}");
    // Forms: every problem on its line, whole.
    let toml = form_description::REFERENCE_TOML
        .replacen("stroke_mm = 25.0", "stroke_mm = 1e308", 1)
        .replacen("height_mm = ", "height_mm = -1e308 # ", 1);
    let form = write(dir.path(), "form.toml", toml);
    let (code, _, stderr) = dressform_within(&["form", "show", "--form", form.to_str().unwrap()]);
    assert_eq!(code, 2, "{stderr}");
    assert!(stderr.contains("`stroke_mm` = 1e308 must be in 0.01..=655.34"), "{stderr}");
    assert!(stderr.contains("`height_mm` = -1e308 must be a height above the floor"), "{stderr}");
    assert!(stderr.lines().all(|l| l.len() < 200) && !stderr.contains("more characters"));
}

/// Issue 29: the exit-3 summary of a form that could not take the shape was cut mid-number
/// ("(6... (26 more characters)"); it lists the rings furthest off and ends "and N more".
#[test]
#[cfg(feature = "simulator")] // drives the simulated form
fn a_long_shape_summary_ends_with_how_many_more() {
    let dir = tempfile::tempdir().unwrap();
    let file = write(dir.path(), "setpoints.json", girths_only(5000.0));
    let (code, _, stderr) = dressform_within(&["drive", file.to_str().unwrap(), "--sim"]);
    assert_eq!(code, 3, "{stderr}");
    assert_one_clean_line(&stderr);
    assert!(stderr.contains("could not take the shape (tolerance 5 mm): "), "{stderr}");
    assert!(!stderr.contains("more characters"), "{stderr}");
    let rings = form_description::reference().rings.len();
    let shown = stderr.matches(" mm wanted, ").count();
    assert!(stderr.trim_end().ends_with(&format!(" and {} more", rings - shown)), "{stderr}");
}

/// Issue 29: `--slower 1e308` overflowed the move's duration (exit 1, "the move needs
/// 18446744073709551615 ms"); a factor too large for the move is bad input (exit 2), and
/// the message gives the allowed range, from the longest SYNC (65535 ms).
#[test]
#[cfg(feature = "simulator")] // drives the simulated form
fn slower_than_a_sync_can_carry_is_refused_with_the_range() {
    let dir = tempfile::tempdir().unwrap();
    let chest = serde_json::json!({
        "format": "dressform-setpoints/1", "form": "reference",
        "positions_mm": { "chest-front": 30.0 },
    });
    let file = write(dir.path(), "chest.json", chest.to_string());
    let file = file.to_str().unwrap();
    for slower in ["1e308", "65536", "inf", "NaN", "0.5"] {
        let (code, _, stderr) = dressform_within(&["drive", file, "--sim", "--slower", slower]);
        assert_eq!(code, 2, "{slower}: {stderr}");
        assert_one_clean_line(&stderr);
        assert!(stderr.contains(&format!("--slower: {slower} is not in [1, 65535]")), "{stderr}");
    }
    // Within the SYNC's range but too slow for this move: refused before the SYNC, with the
    // range for the move.
    let (code, _, stderr) = dressform_within(&["drive", file, "--sim", "--slower", "60000"]);
    assert_eq!(code, 2, "{stderr}");
    assert_one_clean_line(&stderr);
    assert!(stderr.contains("more than a SYNC can carry (65535 ms)"), "{stderr}");
    assert!(stderr.contains("so --slower can be 1 to "), "{stderr}");
}

/// Issue 29: the other numbers `drive` takes are refused (exit 2) with one line naming the
/// option and its range: NaN, infinities, negative and huge values.
#[test]
fn numeric_drive_options_name_their_range() {
    let dir = tempfile::tempdir().unwrap();
    let file = write(dir.path(), "setpoints.json", girths_only(900.0));
    let file = file.to_str().unwrap();
    for (option, value, expected) in [
        ("--tolerance", "1e308", "--tolerance: 1e308 is not in (0, 655.34] mm"),
        ("--tolerance", "NaN", "--tolerance: NaN is not in (0, 655.34] mm"),
        ("--tolerance", "0", "--tolerance: 0 is not in (0, 655.34] mm"),
        ("--duration", "1e308", "--duration: 1e308 is not in [0, 65.535] s"),
        ("--duration", "-inf", "--duration: -inf is not in [0, 65.535] s"),
        ("--girth-tolerance", "-1", "--girth-tolerance: -1 is not in [0, inf) mm"),
        ("--girth-tolerance", "inf", "--girth-tolerance: inf is not in [0, inf) mm"),
    ] {
        let option_value = format!("{option}={value}");
        let (code, _, stderr) = dressform_within(&["drive", file, "--sim", &option_value]);
        assert_eq!(code, 2, "{option_value}: {stderr}");
        assert_one_clean_line(&stderr);
        assert!(stderr.contains(expected), "{option_value}: {stderr}");
    }
    // `run`'s smoothing passes: a huge count would run for hours.
    let (code, _, stderr) = dressform_within(&["run", "scan.obj", "--sim", "--smooth", "1000000"]);
    assert_eq!(code, 2, "{stderr}");
    assert!(stderr.contains("'--smooth <SMOOTH>': 1000000 is not in 0..=100"), "{stderr}");
}

/// Issue 29: `model sample --beta 1e9` wrote a body 1e11 mm tall, `1e308` one with `inf`
/// coordinates (exit 0); betas beyond 5 standard deviations are refused (exit 2), and nothing
/// is written.
#[test]
fn betas_beyond_five_sigma_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let body = dir.path().join("body.obj");
    let body = body.to_str().unwrap();
    for beta in ["1e9", "1e308", "-5.5", "0,0,NaN"] {
        let arg = format!("--beta={beta}");
        let (code, _, stderr) = dressform_within(&["model", "sample", &arg, "-o", body]);
        assert_eq!(code, 2, "{beta}: {stderr}");
        assert_one_clean_line(&stderr);
        assert!(stderr.contains("is not in [-5, 5] standard deviations"), "{stderr}");
        assert!(!Path::new(body).exists(), "{beta}: a body was written");
    }
    let (code, _, stderr) = dressform_within(&["model", "sample", "--beta=5,-5", "-o", body]);
    assert_eq!(code, 0, "{stderr}");
    assert_eq!(dressform(&["info", body]).0, 0, "the body at 5 sigma is one `info` reads");
}

/// A body model file whose vertices are not finite is refused: `model sample` never writes
/// NaN or infinite coordinates.
#[test]
fn a_body_model_with_non_finite_vertices_is_refused() {
    use dressform::pose::body_model::{BodyModel, file};
    let dir = tempfile::tempdir().unwrap();
    let mut model = BodyModel::builtin();
    model.mean[7].z = f64::NAN;
    let mut glb = file::to_bytes(&model);
    // The accessor's bounds become `null`: make them numbers (as long, for the chunk's
    // length), so that only the vertex data is wrong.
    let json_len = u32::from_le_bytes(glb[12..16].try_into().unwrap()) as usize;
    let json = &mut glb[20..20 + json_len];
    while let Some(at) = json.windows(4).position(|w| w == b"null") {
        json[at..at + 4].copy_from_slice(b"0   ");
    }
    let path = write(dir.path(), "model.glb", glb);
    let body = dir.path().join("body.obj");
    let (code, _, stderr) = dressform_within(&[
        "model",
        "sample",
        "--model",
        path.to_str().unwrap(),
        "-o",
        body.to_str().unwrap(),
    ]);
    assert_eq!(code, 2, "{stderr}");
    assert!(stderr.contains("model.glb: POSITION of vertex 7 is not finite"), "{stderr}");
    assert!(!body.exists());
}
