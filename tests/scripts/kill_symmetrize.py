#!/usr/bin/env python3
"""kill -9 at random moments of `dressform symmetrize` writing into a directory that holds an
older output set; after every kill the directory must hold the old set or the new set, whole
(issue 16), as plain files (issue 33). After the last kill one complete run must leave no stray
temporaries.

Two option sets (A: the defaults, B: 60 torso layers) make two different output sets; each
round runs the one the directory does not hold, so there is always an older set to replace.
Kill times are spread over the whole run and, more densely, around the moment the outputs are
committed (the end of the run), measured from clean runs first; a quarter of the kills watch
for the new folder built beside the directory and land inside the commit.

Usage: python3 tests/scripts/kill_symmetrize.py [--rounds 100] [--binary PATH] [--scan PATH]
Slow (a full symmetrize run per round): not part of CI. Exit status 0 when every check held.
"""
import argparse
import hashlib
import os
import pathlib
import random
import shutil
import signal
import subprocess
import sys
import tempfile
import time

ROOT = pathlib.Path(__file__).resolve().parents[2]
NAMES = ["mannequin.obj", "measurements.json", "profiles.json"]
OPTIONS = {"A": [], "B": ["--torso-layers", "60"]}


def digest(out):
    """The visible output set: name -> sha256, or None for a name that is missing."""
    found = {}
    for name in NAMES:
        try:
            found[name] = hashlib.sha256((out / name).read_bytes()).hexdigest()
        except FileNotFoundError:
            found[name] = None
    return found


def run(binary, scan, out, which):
    cmd = [str(binary), "symmetrize", str(scan), "-o", str(out), *OPTIONS[which]]
    return subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)


def beside(out):
    """Folders a commit builds beside the output directory (left there only by a kill)."""
    return sorted(p.name for p in out.parent.iterdir() if p.name.startswith(f".{out.name}.dressform-"))


def stray(out):
    """Temporaries a finished run must not leave: folders beside, temporary files, links."""
    left = beside(out)
    left += [p.name for p in out.iterdir() if p.name.startswith(".dressform-") and p.name != ".dressform-outputs"]
    left += [p.name for p in out.iterdir() if p.is_symlink() or not p.is_file()]
    return left


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--rounds", type=int, default=100)
    ap.add_argument("--binary", default=str(ROOT / "target" / "release" / "dressform"))
    ap.add_argument("--scan", help="a scan file (default: the demo's synthetic customer)")
    ap.add_argument("--seed", type=int, default=1)
    args = ap.parse_args()
    random.seed(args.seed)
    binary = pathlib.Path(args.binary)
    work = pathlib.Path(tempfile.mkdtemp(prefix="dressform-kill-"))
    try:
        scan = pathlib.Path(args.scan) if args.scan else None
        if scan is None:
            subprocess.run([str(binary), "demo", "--out", str(work / "demo")], check=True,
                           stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
            scan = work / "scan.ply"
            shutil.copyfile(work / "demo" / "scan.ply", scan)
        # The two sets, and how long a clean run takes.
        sets, durations = {}, []
        for which in "AB":
            ref = work / f"ref-{which}"
            start = time.monotonic()
            p = run(binary, scan, ref, which)
            _, err = p.communicate()
            durations.append(time.monotonic() - start)
            if p.returncode != 0:
                sys.exit(f"reference run {which} failed: {err.decode()}")
            sets[which] = digest(ref)
        assert sets["A"] != sets["B"], "the two option sets must give different outputs"
        duration = max(durations)
        print(f"a clean run takes {duration:.2f} s; killing {args.rounds} runs")

        out = work / "out"
        p = run(binary, scan, out, "A")
        p.communicate()
        holds = "A"
        counts = {"old": 0, "new": 0, "left a folder beside": 0}
        for round_ in range(args.rounds):
            target = "B" if holds == "A" else "A"
            # Half the kills anywhere in the run, a quarter in the last 15%, a quarter inside
            # the commit itself.
            if round_ % 2 == 0:
                delay = random.uniform(0.0, 1.1 * duration)
            else:
                delay = random.uniform(0.85 * duration, 1.05 * duration)
            p = run(binary, scan, out, target)
            if round_ % 4 == 3:
                # Inside the commit: as soon as the new folder appears beside the directory,
                # or a moment later (the swap comes about 13 ms after it).
                later = random.uniform(0.0, 0.02)
                while not beside(out) and p.poll() is None:
                    time.sleep(0.0002)
                delay = "the commit + %.3f" % later
                time.sleep(later)
            else:
                time.sleep(delay)
            p.send_signal(signal.SIGKILL)
            p.wait()
            now = digest(out)
            if now == sets[holds]:
                counts["old"] += 1
            elif now == sets[target]:
                counts["new"] += 1
                holds = target
            else:
                mixed = {n: ("A" if h == sets["A"][n] else "B" if h == sets["B"][n] else h)
                         for n, h in now.items()}
                sys.exit(f"round {round_}: killed after {delay} s, the directory holds a mix: {mixed}")
            if beside(out):
                counts["left a folder beside"] += 1
        print("after each kill the directory held:", counts)

        p = run(binary, scan, out, "B" if holds == "A" else "A")
        _, err = p.communicate()
        if p.returncode != 0:
            sys.exit(f"the run after the kills failed: {err.decode()}")
        left = stray(out)
        if left:
            sys.exit(f"stray temporaries after a complete run: {left}")
        print("a complete run afterwards left no stray temporaries")
    finally:
        shutil.rmtree(work, ignore_errors=True)


if __name__ == "__main__":
    main()
