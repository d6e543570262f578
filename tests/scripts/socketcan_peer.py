#!/usr/bin/env python3
"""python-can as an independent peer of dressform's SocketCAN link (driven by
tests/controller_socketcan.rs).

    socketcan_peer.py <interface> <expect> <reply>

<expect> and <reply> are frames as `ID#DATA` in hex (candump's notation, standard ids only):
opens <interface> with python-can's socketcan interface, prints `ready` once it listens, waits
for a frame with <expect>'s id and checks its data, then sends <reply>. Prints one summary
line; exits with status 1 (and the reason on stderr) when the frame does not come within the
timeout or differs.
"""

import sys
import time

import can

# A local interface delivers in microseconds; the margin is for a loaded test machine.
TIMEOUT_S = 5.0


def fail(reason):
    print(reason, file=sys.stderr)
    sys.exit(1)


def frame(text):
    """`123#0A0B` -> (0x123, b'\\x0a\\x0b')."""
    ident, _, data = text.partition("#")
    return int(ident, 16), bytes.fromhex(data)


def main(interface, expect, reply):
    (want_id, want_data), (reply_id, reply_data) = frame(expect), frame(reply)
    bus = can.Bus(interface="socketcan", channel=interface)
    try:
        print("ready", flush=True)
        deadline = time.monotonic() + TIMEOUT_S
        while True:
            left = deadline - time.monotonic()
            if left <= 0:
                fail(f"no frame with id {want_id:03X} within {TIMEOUT_S} s")
            message = bus.recv(timeout=left)
            if message is None or message.is_extended_id or message.arbitration_id != want_id:
                continue
            got = bytes(message.data)
            if got != want_data:
                fail(f"frame {want_id:03X} carries {got.hex().upper()}, not {want_data.hex().upper()}")
            break
        bus.send(can.Message(arbitration_id=reply_id, is_extended_id=False, data=reply_data))
    finally:
        bus.shutdown()
    print(f"received {expect}, sent {reply}", flush=True)


if __name__ == "__main__":
    if len(sys.argv) != 4:
        fail(__doc__)
    main(*sys.argv[1:])
