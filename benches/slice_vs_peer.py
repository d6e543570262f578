#!/usr/bin/env python3
"""`dressform slice` against the Python peers on one file, in one run (issue 36).

Times the whole `dressform slice MESH --heights ... --json` process (read, clean, canonical
frame, regions, sections, JSON; best of --runs), then the peers' load + slice of the same file
(`../shared/bench/peer_slice.py`: trimesh and Open3D, whichever is installed; best of
--peer-runs), and prints each peer's time over dressform's. The planes are the peer's: evenly
spaced strictly inside the body's height (dressform's canonical frame: mm above the floor).
Issue 36's goal: at least 40 times Open3D's load + slice.

usage: python3 benches/slice_vs_peer.py MESH [--planes 200] [--runs 5] [--peer-runs 1]
       [--up y|z] [--binary target/release/dressform]
Needs `cargo build --release` first; the peers need `pip install trimesh shapely networkx scipy
open3d`. Run it on a quiet machine: it is a benchmark, not a test.
"""
import argparse
import json
import pathlib
import subprocess
import sys
import tempfile
import time

ROOT = pathlib.Path(__file__).resolve().parents[1]
PEER = ROOT.parent / "shared" / "bench" / "peer_slice.py"
# Issue 36: the whole `slice` process at least this many times faster than Open3D's load+slice.
GOAL_OVER_OPEN3D = 40.0


def best_of(runs, command):
    """The shortest wall time of `runs` runs of `command` (s); it must succeed."""
    times = []
    for _ in range(runs):
        start = time.perf_counter()
        subprocess.run(command, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        times.append(time.perf_counter() - start)
    return min(times)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("mesh")
    ap.add_argument("--planes", type=int, default=200)
    ap.add_argument("--runs", type=int, default=5)
    ap.add_argument("--peer-runs", type=int, default=1)
    ap.add_argument("--up", choices=["y", "z"], default=None,
                    help="the file's up axis for the peers (default: as dressform detects it)")
    ap.add_argument("--binary", default=str(ROOT / "target" / "release" / "dressform"))
    a = ap.parse_args()

    info = json.loads(subprocess.run([a.binary, "info", "--json", a.mesh], check=True,
                                     capture_output=True, text=True).stdout)
    height = info["body"]["height_mm"]
    up = a.up or info["frame"]["up"].lstrip("+-")
    if up not in ("y", "z"):
        sys.exit(f"{a.mesh}: up is {info['frame']['up']}; the peer script takes y or z")
    heights = ",".join(f"{height * (k + 0.5) / a.planes:.3f}" for k in range(a.planes))
    ours = best_of(a.runs, [a.binary, "slice", a.mesh, "--heights", heights, "--json"])
    print(f"dressform slice (whole process, best of {a.runs}): {ours * 1e3:.1f} ms")

    peers = {}
    with tempfile.TemporaryDirectory() as tmp:
        out = pathlib.Path(tmp) / "peer.json"
        for _ in range(a.peer_runs):
            subprocess.run([sys.executable, str(PEER), a.mesh, "--planes", str(a.planes),
                            "--up", up, "--json", str(out)], check=True, stdout=subprocess.DEVNULL)
            for r in json.loads(out.read_text()):
                name = r["library"].split()[0]
                peers[name] = min(peers.get(name, float("inf")), r["total_s"])
    if not peers:
        sys.exit("no peer installed: pip install trimesh shapely networkx scipy open3d")
    for name, t in sorted(peers.items()):
        print(f"{name:<9} load + slice (best of {a.peer_runs}): {t * 1e3:8.1f} ms: "
              f"{t / ours:5.1f}x dressform's whole process")
    if "open3d" in peers:
        ratio = peers["open3d"] / ours
        verdict = "held" if ratio >= GOAL_OVER_OPEN3D else "missed"
        print(f"goal: at least {GOAL_OVER_OPEN3D:.0f}x Open3D: {ratio:.1f}x, {verdict}")


if __name__ == "__main__":
    main()
