//! SocketCAN at run time, on a real interface (`$DRESSFORM_CAN_IFACE`, default `vcan0`; create
//! one with `ip link add dev vcan0 type vcan && ip link set up vcan0`): two links opened on it,
//! a packet sent through one arrives at the other unchanged. Opening needs `socket(AF_CAN)`,
//! which some kernels lack (this project's CI machine among them): then the test says so and
//! skips, or fails with `DRESSFORM_REQUIRE_SOCKETCAN=1`. (Frame conversion is unit-tested in
//! `controller::transport::socketcan`.)

use std::time::Duration;

use dressform::controller::transport::Transport;
use dressform::controller::transport::socketcan::SocketCan;
use firmware_protocol::message::Sync;
use firmware_protocol::{Message, Packet};

use crate::common;

/// How long the receiving link waits for the frame: a local interface delivers in
/// microseconds; the margin is for a loaded test machine.
const DELIVERY: Duration = Duration::from_secs(2);

/// Both links on `interface`, or why not.
fn open_pair(interface: &str) -> Result<(SocketCan, SocketCan), String> {
    let open = || SocketCan::open(interface).map_err(|e| e.to_string());
    Ok((open()?, open()?))
}

#[test]
fn a_packet_crosses_a_real_socketcan_interface() {
    let interface = std::env::var("DRESSFORM_CAN_IFACE").unwrap_or_else(|_| "vcan0".into());
    let runtime = tokio::runtime::Builder::new_current_thread().enable_all().build().unwrap();
    // The tokio socket must be opened inside the runtime.
    let pair = runtime.block_on(async { open_pair(&interface) });
    if let Err(why) = &pair {
        assert!(why.contains(&interface), "the error does not name the interface: {why}");
    }
    let Some((mut sender, mut receiver)) = common::or_skip(
        pair,
        &format!("SocketCAN interface {interface}"),
        "DRESSFORM_REQUIRE_SOCKETCAN",
    ) else {
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
}
