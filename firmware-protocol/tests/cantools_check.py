#!/usr/bin/env python3
"""Cross-check of dressform CAN frames against the DBC file with cantools.

Run by tests/cantools.rs: `python3 cantools_check.py DBC < cases.jsonl`. Every input line is
a frame encoded in Rust and the signal values the Rust types say it carries:

    {"id": 705, "data": "01", "signals": {"Command": 1}}

For each, prints one JSON line with what cantools makes of it, using the DBC alone:

    {"name": ..., "length": ..., "is_fd": ..., "decoded": {...}, "encoded": "hex"}

`decoded` is cantools' decoding of `data` and `encoded` its encoding of `signals` (raw values:
no scaling, no value names). The Rust side compares both with its own.
"""

import json
import sys

import cantools


def main() -> None:
    db = cantools.database.load_file(sys.argv[1])
    for line in sys.stdin:
        case = json.loads(line)
        message = db.get_message_by_frame_id(case["id"])
        decoded = message.decode(
            bytes.fromhex(case["data"]), decode_choices=False, scaling=False
        )
        encoded = message.encode(case["signals"], scaling=False, strict=True)
        print(
            json.dumps(
                {
                    "name": message.name,
                    "length": message.length,
                    "is_fd": message.is_fd,
                    "decoded": {name: int(value) for name, value in decoded.items()},
                    "encoded": encoded.hex(),
                }
            )
        )


if __name__ == "__main__":
    main()
