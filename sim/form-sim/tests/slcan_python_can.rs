//! python-can, an independent CAN implementation, against the simulated form: it opens the
//! slcan pseudo-terminal with its `slcan` interface, identifies every node, and reads the
//! candump log the simulator wrote (`slcan_peer.py` does the Python side).
//!
//! Needs `python3` with python-can and pyserial (`python3 -m pip install python-can
//! pyserial`). Without them the test says so and passes, unless `DRESSFORM_REQUIRE_PEERS=1`
//! (as in CI), where it fails.

use std::path::Path;
use std::process::{Command, Output};

use form_description::reference;
use form_sim::serve::{PtyLink, ServeConfig, serve};

fn python_can_available() -> bool {
    crate::skip::or_skip(
        crate::skip::python_modules("can, serial"),
        "python-can or pyserial (`python3 -m pip install python-can pyserial`)",
        "DRESSFORM_REQUIRE_PEERS",
    )
    .is_some()
}

fn peer(args: &[&str]) -> Output {
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/slcan_peer.py");
    let output = Command::new("python3").arg(script).args(args).output().unwrap();
    assert!(
        output.status.success(),
        "slcan_peer.py {args:?} failed:\n{}{}",
        String::from_utf8_lossy(&output.stdout),
        String::from_utf8_lossy(&output.stderr)
    );
    output
}

#[test]
fn python_can_identifies_every_node_over_slcan_and_reads_the_log() {
    if !python_can_available() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let log = dir.path().join("slcan.log");
    let description = reference();
    let nodes = description.nodes.len().to_string();
    let mut config = ServeConfig::new(description, PtyLink::SlcanPty);
    config.log = Some(log.clone());
    let server = serve(config).unwrap();
    let device = server.device_path().to_str().unwrap().to_string();

    let identified = peer(&["identify", &device, &nodes]);
    let summary = String::from_utf8_lossy(&identified.stdout);
    assert!(
        summary.starts_with(&format!("identified nodes={nodes} strokes=[2500, 6000")),
        "{summary}"
    );

    server.shutdown().unwrap();
    let lines = std::fs::read_to_string(&log).unwrap().lines().count();
    let read = peer(&["read-log", log.to_str().unwrap(), &nodes]);
    let summary = String::from_utf8_lossy(&read.stdout);
    assert!(summary.starts_with(&format!("log frames={lines} ")), "{summary}");
}
