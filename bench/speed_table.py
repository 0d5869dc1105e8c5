#!/usr/bin/env python3
"""The speed history of issue 14: kernel paths against their baselines and the fp64
reference, measured in one run of portalsim_bench, printed as a markdown table.

  python3 bench/speed_table.py [--bench build/portalsim_bench] [--repetitions 3]
  python3 bench/speed_table.py --record bench/speed_history.json   # keep this run's ratios
  python3 bench/speed_table.py --check bench/speed_history.json    # exit 1 on a regression
  python3 bench/speed_table.py --previous /tmp/old/portalsim_bench  # add the previous build's kernels

--check fails when a path's kernel/baseline ratio falls more than 20% below the recorded
one. It runs on demand, not in CI's timed tests: timings on a shared machine are noisy,
so every figure is the median over --repetitions runs.
"""
import argparse
import json
import subprocess
import sys

# path -> (kernel benchmark, kernel counter, baseline benchmark, baseline counter,
#          reference benchmark); counters are scenarios/s.
PATHS = {
    "features-only (thesis, sparse, block 10)": (
        "BM_FeaturesVsBaseline/manual_time", "kernel_per_s", "BM_FeaturesVsBaseline/manual_time", "baseline_per_s",
        "BM_Reference/features/64/10/1/real_time"),
    "images, three views, batch 1024": (
        "BM_ImagesVsBaseline/0/manual_time", "kernel_per_s", "BM_ImagesVsBaseline/0/manual_time", "baseline_per_s",
        "BM_Reference/images/64/10/1/real_time"),
    "images with pixel noise, sigma 2": (
        "BM_ImagesVsBaseline/2/manual_time", "kernel_per_s", "BM_ImagesVsBaseline/2/manual_time", "baseline_per_s",
        "BM_StageReference/3/real_time"),
}
FILTER = "FeaturesVsBaseline|Reference/(features|images)|ImagesVsBaseline|StageReference/3"


def run(bench, repetitions):
    out = subprocess.run([bench, "--benchmark_filter=" + FILTER, "--benchmark_format=json",
                          "--benchmark_repetitions=%d" % repetitions, "--benchmark_report_aggregates_only=true"],
                         check=True, capture_output=True, text=True).stdout
    medians = {}
    for b in json.loads(out)["benchmarks"]:
        if b.get("aggregate_name") == "median":
            medians[b["run_name"]] = b
    return medians


def rate(medians, name, counter):
    if name is None:
        return None
    b = medians.get(name)
    if b is None:
        sys.exit("speed_table: benchmark %s did not run" % name)
    return float(b[counter])


def fmt(v):
    if v is None:
        return "—"
    return "%.3gM/s" % (v / 1e6) if v >= 1e6 else "%.3gk/s" % (v / 1e3) if v >= 1e3 else "%.0f/s" % v


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--bench", default="build/portalsim_bench")
    ap.add_argument("--repetitions", type=int, default=3)
    ap.add_argument("--record")
    ap.add_argument("--check")
    ap.add_argument("--previous", help="the previous commit's portalsim_bench, run in the same session")
    a = ap.parse_args()
    medians = run(a.bench, a.repetitions)
    previous = run(a.previous, a.repetitions) if a.previous else None
    rows, ratios = [], {}
    for path, (kb, kc, bb, bc, rb) in PATHS.items():
        k, b = rate(medians, kb, kc), rate(medians, bb, bc)
        r = rate(medians, rb, "items_per_second")
        ratios[path] = k / b if b else None
        row = [path, fmt(k), fmt(b), fmt(r), "%.2fx" % (k / b) if b else "—", "%.0fx" % (k / r)]
        if previous is not None:
            p = previous.get(kb)
            row.append(fmt(float(p[kc])) if p and kc in p else "—")
        rows.append("| " + " | ".join(row) + " |")
    head = ["path", "kernel", "baseline", "fp64 reference", "kernel / baseline", "kernel / reference"]
    if previous is not None:
        head.append("previous build's kernel")
    print("| " + " | ".join(head) + " |")
    print("|" + "---|" * len(head))
    print("\n".join(rows))
    print("\nMedians of %d runs of %s%s, 2 threads." % (a.repetitions, a.bench,
                                                    " and of " + a.previous if a.previous else ""))
    if a.record:
        with open(a.record, "w") as f:
            json.dump(ratios, f, indent=2)
    if a.check:
        with open(a.check) as f:
            recorded = json.load(f)
        failed = [p for p, r in ratios.items() if r and recorded.get(p) and r < 0.8 * recorded[p]]
        for p in failed:
            print("regression: %s kernel/baseline %.2f, recorded %.2f" % (p, ratios[p], recorded[p]), file=sys.stderr)
        return 1 if failed else 0
    return 0


if __name__ == "__main__":
    sys.exit(main())
