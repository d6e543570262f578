//! `dressform sim`: starts a simulated form on a pseudo-terminal and prints its path.

// Drives the simulated form (the `simulator` feature).
#![cfg(feature = "simulator")]

use std::io::{BufRead, BufReader};
use std::process::{Command, Stdio};

#[test]
fn sim_prints_a_pseudo_terminal_that_exists() {
    let form = concat!(env!("CARGO_MANIFEST_DIR"), "/form-description/forms/reference.toml");
    for link in ["--serial-pty", "--slcan-pty"] {
        let mut child = Command::new(env!("CARGO_BIN_EXE_dressform"))
            .args(["sim", "--form", form, link])
            .stdout(Stdio::piped())
            .stderr(Stdio::null())
            .spawn()
            .expect("dressform sim starts");
        let mut line = String::new();
        BufReader::new(child.stdout.take().expect("stdout")).read_line(&mut line).expect("a line");
        let path = line.trim();
        assert!(path.starts_with("/dev/"), "{link}: {path:?}");
        assert!(std::path::Path::new(path).exists(), "{link}: {path} exists");
        child.kill().expect("stop the simulator");
        child.wait().expect("it stops");
    }
}
