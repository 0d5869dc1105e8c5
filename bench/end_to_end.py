#!/usr/bin/env python3
"""End-to-end rate of `portalsim generate` against the destination's own write speed.

Each round runs, interleaved: `dd` writing fresh bytes to the destination (oflag=direct
unless it is a tmpfs, which has no direct I/O), then every given build's `generate` into a
new folder there, a different build first in each round (use an even number of rounds
for two builds). Prints a markdown table of medians: the run's scenarios/s from its
summary line, its bytes/s, its share of dd's rate, and the whole command's wall and CPU time
(user + system, every thread; the figure that other jobs on the machine disturb least).

  python3 bench/end_to_end.py --dest /dev/shm --count 5000 --rounds 3 \\
      --build new=build/portalsim --build old=OLD/portalsim \\
      -- --seed 1 --rule gun --what images --format h5
"""
import argparse
import os
import re
import resource
import shutil
import statistics
import subprocess
import tempfile
import time


def folder_bytes(path):
    total = 0
    for root, _, files in os.walk(path):
        for f in files:
            total += os.path.getsize(os.path.join(root, f))
    return total


def is_tmpfs(path):
    out = subprocess.run(["stat", "-f", "-c", "%T", path], capture_output=True, text=True).stdout.strip()
    return out == "tmpfs"


def dd_rate(dest, mb):
    """Bytes/s of dd writing `mb` MiB of fresh bytes to a new file in dest."""
    target = os.path.join(dest, "portalsim-dd-%d" % os.getpid())
    args = ["dd", "if=/dev/zero", "of=" + target, "bs=1M", "count=%d" % mb]
    if not is_tmpfs(dest):
        args.append("oflag=direct")
    t0 = time.monotonic()
    subprocess.run(args, check=True, capture_output=True)
    seconds = time.monotonic() - t0
    os.remove(target)
    return mb * 1048576 / seconds


def run_generate(binary, dest, count, extra):
    out = tempfile.mkdtemp(prefix="portalsim-e2e-", dir=dest)
    shutil.rmtree(out)
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.monotonic()
    p = subprocess.run([binary, "generate", "--count", str(count), "--out", out] + extra,
                       capture_output=True, text=True)
    wall = time.monotonic() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    if p.returncode != 0:
        raise SystemExit("%s failed (%d): %s" % (binary, p.returncode, p.stderr[-2000:]))
    m = re.search(r"([0-9.]+) scenarios/s", p.stdout + p.stderr)
    if not m:
        raise SystemExit("%s: no scenarios/s in its summary line" % binary)
    size = folder_bytes(out)
    shutil.rmtree(out)
    return float(m.group(1)), wall, cpu, size


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--dest", required=True, help="folder on the filesystem to measure")
    ap.add_argument("--count", type=int, default=5000)
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--dd-mb", type=int, default=1000, help="MiB that dd writes per round")
    ap.add_argument("--build", action="append", required=True, help="LABEL=PATH of a portalsim binary")
    ap.add_argument("generate_args", nargs=argparse.REMAINDER, help="-- then generate's arguments")
    a = ap.parse_args()
    extra = [x for x in a.generate_args if x != "--"] + ["--quiet"]
    builds = [b.split("=", 1) for b in a.build]
    dd, sizes, loads = [], {}, []
    rates, walls, cpus = ({l: [] for l, _ in builds} for _ in range(3))
    for round_ in range(a.rounds):
        loads.append(os.getloadavg()[0])
        dd.append(dd_rate(a.dest, a.dd_mb))
        # Each build goes first in turn: on a virtual machine a run that touches memory the
        # guest has not used for a while pays for the host to back it, and the run after it
        # reuses the pages it freed (50,000 scenarios: whichever build ran second was 20-30%
        # faster).
        k = round_ % len(builds)
        for label, path in builds[k:] + builds[:k]:
            r, w, c, s = run_generate(path, a.dest, a.count, extra)
            rates[label].append(r)
            walls[label].append(w)
            cpus[label].append(c)
            sizes[label] = s
    loads.append(os.getloadavg()[0])
    dd_med = statistics.median(dd)
    kind = "tmpfs" if is_tmpfs(a.dest) else "direct I/O"
    print("%s (%s), %d scenarios, medians of %d rounds, load average %.1f to %.1f; "
          "dd writes fresh bytes at %.2f GB/s" % (a.dest, kind, a.count, a.rounds, min(loads), max(loads), dd_med / 1e9))
    print()
    print("| build | scenarios/s | bytes per scenario | GB/s written | share of dd | wall, whole command "
          "| CPU, whole command |")
    print("|---|---|---|---|---|---|---|")
    for label, _ in builds:
        r = statistics.median(rates[label])
        per = sizes[label] / a.count
        print("| %s | %s | %s | %.2f | %.0f%% | %.2f s | %.2f s |" %
              (label, f"{r:,.0f}", f"{per:,.0f}", r * per / 1e9, 100 * r * per / dd_med,
               statistics.median(walls[label]), statistics.median(cpus[label])))


if __name__ == "__main__":
    main()
