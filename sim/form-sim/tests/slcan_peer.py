"""python-can as an independent peer of the simulated form (driven by slcan_python_can.rs).

    slcan_peer.py identify <device> <nodes>
        Opens the simulator's slcan pseudo-terminal with python-can's slcan interface, sends
        a broadcast IdentifyRequest and checks that nodes 1..<nodes> each answer Identity
        (protocol 1.x, 1..8 actuators) and Capabilities.

    slcan_peer.py read-log <log> <nodes>
        Reads the simulator's candump log with python-can's CanutilsLogReader and checks that
        it holds the IdentifyRequest and every node's Identity, in time order.

Both print one summary line and exit with status 1 (and the reason on stderr) on failure.
CAN ids are `code << 6 | address` (firmware-protocol/README.md): IdentifyRequest is code
14, Identity 15, Capabilities 16.
"""

import sys
import time

import can

IDENTIFY_REQUEST, IDENTITY, CAPABILITIES = 14, 15, 16


def fail(reason):
    print(reason, file=sys.stderr)
    sys.exit(1)


def identify(device, nodes):
    bus = can.Bus(interface="slcan", channel=device, bitrate=1_000_000, sleep_after_open=0)
    identities, capabilities = {}, {}
    try:
        bus.send(can.Message(arbitration_id=IDENTIFY_REQUEST << 6, is_extended_id=False, data=[]))
        deadline = time.monotonic() + 3.0
        while time.monotonic() < deadline and (
            len(identities) < nodes or len(capabilities) < nodes
        ):
            message = bus.recv(timeout=0.1)
            if message is None or message.is_extended_id:
                continue
            code, node = message.arbitration_id >> 6, message.arbitration_id & 0x3F
            if code == IDENTITY:
                identities[node] = bytes(message.data)
            elif code == CAPABILITIES:
                capabilities[node] = bytes(message.data)
    finally:
        bus.shutdown()
    expected = set(range(1, nodes + 1))
    if set(identities) != expected or set(capabilities) != expected:
        fail(f"answers from {sorted(identities)} / {sorted(capabilities)}, expected {sorted(expected)}")
    for node, data in identities.items():
        major, actuators = data[0], data[5]
        if len(data) != 6 or major != 1 or not 1 <= actuators <= 8:
            fail(f"node {node}: bad Identity {data.hex()}")
    strokes = [int.from_bytes(capabilities[n][0:2], "little") for n in sorted(capabilities)]
    print(f"identified nodes={len(identities)} strokes={strokes}")


def read_log(path, nodes):
    messages = list(can.CanutilsLogReader(path))
    frames = [m for m in messages if not m.is_error_frame]
    ids = [m.arbitration_id for m in frames]
    if IDENTIFY_REQUEST << 6 not in ids:
        fail("the log has no IdentifyRequest")
    answered = {i & 0x3F for i in ids if i >> 6 == IDENTITY}
    if answered != set(range(1, nodes + 1)):
        fail(f"the log has Identity from {sorted(answered)}")
    times = [m.timestamp for m in messages]
    if any(later < earlier for earlier, later in zip(times, times[1:])):
        fail("log timestamps go backwards")
    if {m.channel for m in messages} != {"can0"} or any(m.is_fd for m in messages):
        fail("unexpected channel or FD frame in the log")
    print(f"log frames={len(messages)} span={times[-1] - times[0]:.3f}s")


if __name__ == "__main__":
    if len(sys.argv) != 4 or sys.argv[1] not in ("identify", "read-log"):
        fail(__doc__)
    command, target, count = sys.argv[1], sys.argv[2], int(sys.argv[3])
    (identify if command == "identify" else read_log)(target, count)
