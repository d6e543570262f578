//! SocketCAN at run time, on a real interface (`$DRESSFORM_CAN_IFACE`, default `vcan0`; create
//! one with `ip link add dev vcan0 type vcan && ip link set up vcan0`): two dressform links
//! opened on it, a packet sent through one arrives at the other unchanged; then python-can, an
//! independent implementation, on the same interface receives the frame of a packet dressform
//! sends (id and data checked) and answers with one dressform must decode. (Frame conversion
//! is unit-tested in `controller::transport::socketcan`.)
//!
//! When it runs, the rule: SocketCAN is a capability of the kernel, not a tool to install.
//! Opening needs `socket(AF_CAN)` and the interface, which some kernels lack: then the test
//! prints that it did not run and why (no SocketCAN in the kernel, or no such interface) and
//! passes, or fails with `DRESSFORM_REQUIRE_SOCKETCAN=1`. CI (`.ci/run`) creates `vcan0` where
//! the kernel allows it and sets that variable there; where not, it says in its summary that
//! this test did not run. It does not follow `DRESSFORM_REQUIRE_PEERS`: CI sets that to require
//! the peer tools it installs, and a kernel feature a machine lacks is not something CI can
//! install. Once SocketCAN is there, python-can is a peer like any other: missing, the peer part
//! skips, or fails with `DRESSFORM_REQUIRE_PEERS=1`. Every outcome after that is checked: a
//! frame that does not arrive, or arrives changed, either way, fails the test.

// Needs the SocketCAN transport (the `socketcan` feature).
#![cfg(feature = "socketcan")]

use std::io::{BufRead, BufReader, Read};
use std::path::Path;
use std::process::{Command, Stdio};
use std::time::Duration;

use dressform::form::controller::transport::Transport;
use dressform::form::controller::transport::socketcan::SocketCan;
use embedded_can::Frame as _;
use firmware_protocol::message::Sync;
use firmware_protocol::{Message, Packet};

use crate::common;

/// How long the receiving link waits for the frame: a local interface delivers in
/// microseconds; the margin is for a loaded test machine (the peer script waits as long).
const DELIVERY: Duration = Duration::from_secs(5);

/// Both links on `interface`, or why not.
fn open_pair(interface: &str) -> Result<(SocketCan, SocketCan), String> {
    let open = || SocketCan::open(interface).map_err(|e| e.to_string());
    Ok((open()?, open()?))
}

/// Why `interface` could not be opened (`error`), in plain words: opening looks the interface
/// up before it makes the socket, so a kernel without SocketCAN also reports "No such device";
/// a CAN socket bound to no interface in particular tells the two apart.
fn why_not(interface: &str, error: &str) -> String {
    use socketcan::Socket as _;
    match socketcan::CanSocket::open_iface(0) {
        Err(e) => format!(
            "this kernel has no SocketCAN (socket(AF_CAN) fails: {e}); opening {interface}: {error}"
        ),
        Ok(_) => format!(
            "the kernel has SocketCAN, but opening {interface} fails: {error} (create it: \
             `ip link add dev {interface} type vcan && ip link set up {interface}`)"
        ),
    }
}

#[test]
fn a_packet_crosses_a_real_socketcan_interface() {
    let interface = std::env::var("DRESSFORM_CAN_IFACE").unwrap_or_else(|_| "vcan0".into());
    let runtime = tokio::runtime::Builder::new_current_thread().enable_all().build().unwrap();
    // The tokio socket must be opened inside the runtime.
    let pair = runtime.block_on(async { open_pair(&interface) }).map_err(|error| {
        assert!(error.contains(&interface), "the error does not name the interface: {error}");
        why_not(&interface, &error)
    });
    let Some((mut sender, mut receiver)) = common::or_skip(
        pair,
        &format!("SocketCAN interface {interface}"),
        "DRESSFORM_REQUIRE_SOCKETCAN",
    ) else {
        eprintln!(
            "the SocketCAN runtime test did not run: nothing was sent on {interface} \
             (DRESSFORM_REQUIRE_SOCKETCAN=1 makes this a failure)"
        );
        return;
    };
    let packet = Packet::broadcast(Message::Sync(Sync { duration_ms: 1234 }));
    let received = runtime.block_on(async {
        sender.send(packet).await.expect("send");
        tokio::time::timeout(DELIVERY, receiver.recv()).await
    });
    let received =
        received.unwrap_or_else(|_| panic!("nothing arrived on {interface} within {DELIVERY:?}"));
    assert_eq!(received.expect("receive"), packet);

    let peer = common::or_skip(
        common::python_modules("can"),
        "python-can (`python3 -m pip install python-can`)",
        "DRESSFORM_REQUIRE_PEERS",
    );
    if peer.is_some() {
        runtime.block_on(python_can_exchanges_frames(&interface, &mut sender, &mut receiver));
    }
}

/// A packet's CAN frame in candump's notation, `ID#DATA` (hex).
fn candump(packet: &Packet) -> String {
    let frame = firmware_protocol::can::encode(packet).expect("a broadcast Sync encodes");
    let data: String = frame.data().iter().map(|b| format!("{b:02X}")).collect();
    format!("{:03X}#{data}", frame.standard_id().as_raw())
}

/// python-can (`tests/scripts/socketcan_peer.py`) receives what `sender` sends and answers;
/// `receiver` must decode the answer.
async fn python_can_exchanges_frames(
    interface: &str,
    sender: &mut SocketCan,
    receiver: &mut SocketCan,
) {
    let sent = Packet::broadcast(Message::Sync(Sync { duration_ms: 1234 }));
    let answer = Packet::broadcast(Message::Sync(Sync { duration_ms: 4321 }));
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/scripts/socketcan_peer.py");
    let mut peer = Command::new("python3")
        .arg(script)
        .args([interface, &candump(&sent), &candump(&answer)])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("python3 runs");
    let mut stdout = BufReader::new(peer.stdout.take().expect("piped"));
    let mut ready = String::new();
    let _ = stdout.read_line(&mut ready);
    let mut why = String::new();
    if ready.trim() != "ready" {
        let _ = peer.stderr.take().expect("piped").read_to_string(&mut why);
        panic!("socketcan_peer.py did not start listening: {ready}{why}");
    }
    sender.send(sent).await.expect("send");
    // The receiver also hears `sent` (a CAN interface loops frames back to other sockets).
    let heard = tokio::time::timeout(DELIVERY, async {
        loop {
            let packet = receiver.recv().await.expect("receive");
            if packet != sent {
                return packet;
            }
        }
    })
    .await;
    let output = peer.wait_with_output().expect("the peer ends");
    let mut said = String::new();
    let _ = stdout.read_to_string(&mut said);
    assert!(
        output.status.success(),
        "python-can did not receive {} as sent: {}{}",
        candump(&sent),
        said,
        String::from_utf8_lossy(&output.stderr)
    );
    let heard = heard.unwrap_or_else(|_| panic!("python-can's answer did not arrive: {said}"));
    assert_eq!(heard, answer, "python-can sent {}", candump(&answer));
}
