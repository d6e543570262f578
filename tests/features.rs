//! A dressform built without the simulator or without SocketCAN (cargo features `simulator`,
//! `socketcan`): the commands and options that need them still parse and refuse with one
//! line naming the feature, exit status 2. With the default features there is nothing to
//! check here (the other tests use both).

#[cfg(not(all(feature = "simulator", feature = "socketcan")))]
use crate::common::dressform;

/// `args` is refused with exit status 2 and a one-line message naming `missing` (as the
/// refusal names it) and the way back.
#[cfg(not(all(feature = "simulator", feature = "socketcan")))]
fn refused(args: &[&str], missing: &str) {
    let (code, stdout, stderr) = dressform(args);
    assert_eq!(code, 2, "{args:?}: {stderr}");
    assert!(stdout.is_empty(), "{args:?}: {stdout}");
    assert_eq!(stderr.lines().count(), 1, "{args:?}: {stderr}");
    assert!(
        stderr.contains(&format!("this dressform was built without {missing}"))
            && stderr.contains("rebuild with default features"),
        "{args:?}: {stderr}"
    );
}

/// A set-point file the reference form can take, in `dir`.
#[cfg(not(all(feature = "simulator", feature = "socketcan")))]
fn setpoints(dir: &tempfile::TempDir) -> String {
    let path = dir.path().join("setpoints.json");
    let text = r#"{"format": "dressform-setpoints/1", "form": "reference", "positions_mm": {"chest-l1": 3.5}}"#;
    std::fs::write(&path, text).unwrap();
    path.display().to_string()
}

#[cfg(not(feature = "simulator"))]
#[test]
fn without_the_simulator_its_commands_refuse() {
    const SIMULATOR: &str = "the simulator (cargo feature `simulator`)";
    refused(&["demo"], SIMULATOR);
    refused(&["demo", "--out", "x", "--seed", "3"], SIMULATOR);
    refused(&["sim", "--serial-pty"], SIMULATOR);
    let dir = tempfile::tempdir().unwrap();
    let file = setpoints(&dir);
    refused(&["drive", &file, "--sim"], SIMULATOR);
    refused(&["status", "--sim"], SIMULATOR);
    refused(&["reset", "--sim"], SIMULATOR);
    refused(&["estop", "--sim"], SIMULATOR);
}

#[cfg(not(feature = "socketcan"))]
#[test]
fn without_socketcan_can_refuses() {
    const SOCKETCAN: &str = "SocketCAN (cargo feature `socketcan`)";
    let dir = tempfile::tempdir().unwrap();
    let file = setpoints(&dir);
    refused(&["drive", &file, "--can", "vcan0"], SOCKETCAN);
    refused(&["status", "--can", "vcan0"], SOCKETCAN);
    refused(&["estop", "--can", "vcan0"], SOCKETCAN);
}
