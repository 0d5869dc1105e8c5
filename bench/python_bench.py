#!/usr/bin/env python3
"""Scenarios/s that reach Python, beside the kernels' own rate and the file loaders (issue 27).

    /usr/bin/python3 bench/python_bench.py --portalsim build/portalsim [--repeats 3] [--out table.md]

In one run, on one machine (medians of --repeats runs each):
- in kernel: the backend's own rate (portalsim.Generator.times()["kernels"], the time in the
  kernels alone), for the batches the NumPy row below delivers;
- NumPy: Generator.batch over --scenarios scenarios, batches of --batch (prefetch on), each
  batch's arrays touched (one byte of each) and dropped;
- torch: StreamDataset(batched=True) through a DataLoader(batch_size=None) with 0, 1 and 2
  workers, as uint8 tensors (scale=False) and as float32 in [0, 1] (scale=True);
- H5Dataset: a data.h5 of the same scenarios (generate --format h5 on /dev/shm), read in
  random order by DataLoader(batch_size=256, shuffle=True);
- PNG folder: images/<index>/upper.png and lower.png (generate's image folders) read with PIL.
for thesis images and physics images (three views, `what="images"`, the default tier), and the
in-kernel and NumPy rows again with only upper, lower and label made (Generator(datasets=...)), then
memory: RSS over --long features-only scenarios streamed (features-only keeps 10 million
feasible in minutes; images at the same batch size hold the same buffers, larger).
Prints a Markdown table (and writes it to --out) with `uptime` before and after.
"""
import argparse
import datetime
import os
import pathlib
import shutil
import statistics
import subprocess
import sys
import tempfile
import time

import numpy as np
import torch
from torch.utils.data import DataLoader

import portalsim
from portalsim.torch import H5Dataset, StreamDataset

MODELS = {"thesis images": dict(what="images"), "physics images": dict(what="images", model="physics")}
# The same runs with only the MMW views and the label made (Generator(datasets=...)): what a
# model trained on upper and lower, as StreamDataset's default views, receives.
MMW = ("upper", "lower", "label")
SELECTED = {f"{name} ({', '.join(MMW)})": (kw, MMW) for name, kw in MODELS.items()}


def rss_mib():
    with open("/proc/self/status") as f:
        for line in f:
            if line.startswith("VmRSS:"):
                return int(line.split()[1]) / 1024
    return float("nan")


def median_rate(fn, repeats):
    """fn() -> (scenarios, seconds); the median of the rates, and all of them."""
    rates = []
    for _ in range(repeats):
        n, s = fn()
        rates.append(n / s)
    return statistics.median(rates), rates


def numpy_rate(kw, n, batch, datasets=None):
    """(delivered rate, in-kernel rate) of Generator.batch."""
    gen = portalsim.Generator(seed=1, datasets=datasets, **kw)
    gen.batch(0, batch)  # the kernels' build and the first buffers, not timed
    before = gen.times()
    t0 = time.perf_counter()
    for s in range(batch, batch + n, batch):
        b = gen.batch(s, batch)
        for a in b.values():
            a.reshape(-1)[0]  # touch: the arrays are there
        del b
    wall = time.perf_counter() - t0
    after = gen.times()
    kernels = after["kernels"] - before["kernels"]
    # The generator rendered one batch ahead; the kernels' time counts every batch it made.
    return n / wall, (after["scenarios"] - before["scenarios"]) / kernels


def torch_rate(kw, n, batch, workers, scale):
    ds = StreamDataset(seed=1, views=("upper", "lower"), start=0, count=n, batch=batch, batched=True, scale=scale,
                       **kw)
    # Timed from the first block on: the workers' start and the kernels' build are not.
    it = iter(DataLoader(ds, batch_size=None, num_workers=workers))
    next(it)
    t0 = time.perf_counter()
    got = 0
    for x, y in it:
        got += len(y)
    return got, time.perf_counter() - t0


def h5_rate(path, n):
    ds = H5Dataset(path, views=("upper", "lower"))
    t0 = time.perf_counter()
    got = 0
    for x, y in DataLoader(ds, batch_size=256, shuffle=True):
        got += len(y)
        if got >= n:
            break
    return got, time.perf_counter() - t0


def png_rate(folder, n):
    from PIL import Image

    dirs = sorted(p for p in (folder / "images").iterdir())[:n]
    t0 = time.perf_counter()
    for d in dirs:
        np.asarray(Image.open(d / "upper.png"))
        np.asarray(Image.open(d / "lower.png"))
    return len(dirs), time.perf_counter() - t0


def memory(n, batch):
    """RSS (MiB) over n features-only scenarios streamed: after the first batch, the most, the last."""
    gen = portalsim.Generator(seed=1, what="features")
    gen.batch(0, batch)
    first = rss_mib()
    most = first
    t0 = time.perf_counter()
    for s in range(batch, n + batch, batch):
        b = gen.batch(s, batch)
        b["features"][0, 0]
        del b
        most = max(most, rss_mib())
    return first, most, rss_mib(), n / (time.perf_counter() - t0)


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--portalsim", required=True, help="the portalsim binary (for the data.h5 and PNG sets)")
    p.add_argument("--repeats", type=int, default=3)
    p.add_argument("--scenarios", type=int, default=65536, help="thesis scenarios per measurement (physics: 1/8)")
    p.add_argument("--batch", type=int, default=1024)
    p.add_argument("--long", type=int, default=10_000_000, help="features-only scenarios for the memory row")
    p.add_argument("--out", help="also write the table here")
    a = p.parse_args()
    load_before = subprocess.run(["uptime"], capture_output=True, text=True).stdout.strip()
    rows = []
    work = pathlib.Path(tempfile.mkdtemp(prefix="portalsim-bench-", dir="/dev/shm"))
    try:
        # DataLoader workers first: they fork, and PoCL hangs in a child forked from a process
        # that had made an OpenCL context, so this process renders nothing until they are done.
        counts = {name: a.scenarios if "thesis" in name else max(a.batch, a.scenarios // 8) for name in MODELS}
        later = {name: [] for name in MODELS}
        for name, kw in MODELS.items():
            for scale in (False, True):
                for w in (1, 2):
                    r, rs = median_rate(lambda: torch_rate(kw, counts[name], a.batch, w, scale), a.repeats)
                    later[name].append((name, f"torch {'float32' if scale else 'uint8'}, DataLoader {w} workers", r, rs))
        for name, kw in MODELS.items():
            n = counts[name]
            delivered, kernel = zip(*(numpy_rate(kw, n, a.batch) for _ in range(a.repeats)))
            rows.append((name, "in kernel (backend alone)", statistics.median(kernel), kernel))
            rows.append((name, f"NumPy, Generator.batch({a.batch})", statistics.median(delivered), delivered))
            for scale in (False, True):
                r, rs = median_rate(lambda: torch_rate(kw, n, a.batch, 0, scale), a.repeats)
                rows.append((name, f"torch {'float32' if scale else 'uint8'}, DataLoader 0 workers", r, rs))
            rows += later[name]
            h5 = work / name.split()[0]
            subprocess.run([a.portalsim, "generate", "--seed", "1", "--count", str(min(n, 8192)), "--format", "h5",
                            "--out", str(h5), "--quiet"] + [f"--{k}={v}" for k, v in kw.items()], check=True)
            r, rs = median_rate(lambda: h5_rate(h5 / "data.h5", min(n, 8192)), a.repeats)
            rows.append((name, "H5Dataset, DataLoader shuffle, 0 workers", r, rs))
            png = work / (name.split()[0] + "-png")
            subprocess.run([a.portalsim, "generate", "--seed", "1", "--count", "300", "--out", str(png), "--quiet"] +
                           [f"--{k}={v}" for k, v in kw.items()], check=True)
            r, rs = median_rate(lambda: png_rate(png, 300), a.repeats)
            rows.append((name, "PNG folder (upper, lower), PIL", r, rs))
            shutil.rmtree(h5)
            shutil.rmtree(png)
        for name, (kw, datasets) in SELECTED.items():
            n = counts[name.split(" (")[0]]
            delivered, kernel = zip(*(numpy_rate(kw, n, a.batch, datasets) for _ in range(a.repeats)))
            rows.append((name, "in kernel (backend alone)", statistics.median(kernel), kernel))
            rows.append((name, f"NumPy, Generator.batch({a.batch})", statistics.median(delivered), delivered))
        first, most, last, rate = memory(a.long, 16384)
    finally:
        shutil.rmtree(work, ignore_errors=True)
    load_after = subprocess.run(["uptime"], capture_output=True, text=True).stdout.strip()
    lines = [f"Measured {datetime.datetime.now(datetime.timezone.utc):%Y-%m-%d %H:%M} UTC, "
             f"{os.cpu_count()} cores, {a.repeats} repeats (median; all runs in brackets).",
             f"Load before: `{load_before}`; after: `{load_after}`.", "",
             "| scenarios | delivered as | scenarios/s (median) | runs | % of in kernel |",
             "|---|---|---:|---|---:|"]
    kernel_of = {m: r for m, what, r, _ in rows if what.startswith("in kernel")}
    for m, what, r, rs in rows:
        lines.append(f"| {m} | {what} | {r:,.0f} | {', '.join(f'{x:,.0f}' for x in rs)} | "
                     f"{100 * r / kernel_of[m]:.0f}% |")
    lines += ["", f"Memory: {a.long:,} features-only scenarios streamed (Generator.batch(16384)) at {rate:,.0f}/s: "
              f"RSS {first:.0f} MiB after the first batch, at most {most:.0f} MiB, {last:.0f} MiB at the end."]
    text = "\n".join(lines)
    print(text)
    if a.out:
        pathlib.Path(a.out).write_text(text + "\n")


if __name__ == "__main__":
    sys.exit(main())
