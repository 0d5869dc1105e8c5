#!/usr/bin/env python3
"""Ranks against one process: generate's wall time for a features-only and an images data
set, one process (2 threads) against mpirun -np 1 and -np 2 (--bind-to none: a rank
threads over its node), median of N runs, as a
Markdown table. Every ranked result is checked byte for byte against the one-process one.

  python3 bench/scaling.py --portalsim build/portalsim [--repetitions 3] [--work /tmp/scaling]
"""
import argparse
import filecmp
import os
import shutil
import statistics
import subprocess
import sys
import time

CASES = {
    "features-only, npy": ["--count", "200000", "--seed", "1", "--rule", "gun", "--format", "npy"],
    "images, PNG folders": ["--count", "3000", "--seed", "1", "--rule", "gun", "--what", "images"],
}


def same_tree(a, b):
    c = filecmp.dircmp(a, b)
    if c.left_only or c.right_only or c.funny_files:
        return False
    _, mismatch, errors = filecmp.cmpfiles(a, b, c.common_files, shallow=False)
    return not mismatch and not errors and all(same_tree(os.path.join(a, d), os.path.join(b, d)) for d in c.common_dirs)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--portalsim", required=True)
    ap.add_argument("--repetitions", type=int, default=3)
    ap.add_argument("--work", default="/tmp/portalsim-scaling")
    a = ap.parse_args()
    exe = os.path.abspath(a.portalsim)
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    ways = {
        "one process, 2 threads": lambda out, spec: [exe, "generate", *spec, "--threads", "2", "--quiet", "--out", out],
        "mpirun -np 1": lambda out, spec: ["mpirun", "--bind-to", "none", "-np", "1", exe, "generate", *spec, "--quiet", "--out", out],
        "mpirun -np 2": lambda out, spec: ["mpirun", "--bind-to", "none", "-np", "2", exe, "generate", *spec,
                                           "--quiet", "--out", out],
    }
    print(f"| data set | way | wall s (median of {a.repetitions}) | scenarios/s | vs one process |")
    print("| --- | --- | --- | --- | --- |")
    for case, spec in CASES.items():
        count = int(spec[spec.index("--count") + 1])
        base = None
        for way, command in ways.items():
            walls = []
            for r in range(a.repetitions):
                out = os.path.join(a.work, f"out{r}")
                shutil.rmtree(a.work, ignore_errors=True)
                os.makedirs(a.work)
                t = time.monotonic()
                subprocess.run(command(out, spec), check=True, env=env, stdout=subprocess.DEVNULL)
                walls.append(time.monotonic() - t)
                ref = os.path.join(a.work + "-ref", case.split(",")[0])
                if not os.path.isdir(ref):
                    shutil.copytree(out, ref)
                elif not same_tree(ref, out):
                    sys.exit(f"scaling: {way} on {case} differs from the first run")
            wall = statistics.median(walls)
            base = base or wall
            print(f"| {case} ({count:,}) | {way} | {wall:.2f} | {count / wall:,.0f} | {base / wall:.2f}x |", flush=True)
    shutil.rmtree(a.work, ignore_errors=True)
    shutil.rmtree(a.work + "-ref", ignore_errors=True)


if __name__ == "__main__":
    main()
