#!/usr/bin/env python3
"""The speed history of issue 14: kernel paths against their plain loops and the fp64
reference, measured in one run of `portalsim bench --json`, printed as a markdown table.

  python3 bench/speed_table.py [--portalsim build/portalsim] [--repetitions 3] [--quick]
  python3 bench/speed_table.py --json bench.json        # a saved `portalsim bench --json`, not run again
  python3 bench/speed_table.py --record bench/speed_history.json   # keep this run's ratios
  python3 bench/speed_table.py --check bench/speed_history.json    # exit 1 on a regression
  python3 bench/speed_table.py --previous /tmp/old/portalsim        # add the previous build's kernels

--check fails when a path's kernel/loop ratio falls more than 20% below the recorded
one. It runs on demand, not in CI's timed tests: timings on a shared machine are noisy,
so every figure is the median over --repetitions runs (portalsim bench takes them).
"""
import argparse
import json
import subprocess
import sys


def run(portalsim, a):
    cmd = [portalsim, "bench", "--json", "--repetitions", str(a.repetitions)]
    if a.quick:
        cmd.append("--quick")
    if a.device:
        cmd += ["--device", a.device]
    if a.dir:
        cmd += ["--dir", a.dir]
    out = subprocess.run(cmd, check=True, stdout=subprocess.PIPE, text=True).stdout
    return json.loads(out)


def rate(cell):
    return cell.get("per_s") if cell else None


def fmt(v):
    if v is None:
        return "—"
    return "%.3gM/s" % (v / 1e6) if v >= 1e6 else "%.3gk/s" % (v / 1e3) if v >= 1e3 else "%.3g/s" % v


def ratio(a, b, form="%.2fx"):
    return form % (a / b) if a and b else "—"


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--portalsim", default="build/portalsim")
    ap.add_argument("--json", help="read this saved output of `portalsim bench --json` instead of running it")
    ap.add_argument("--repetitions", type=int, default=3)
    ap.add_argument("--quick", action="store_true", help="portalsim bench --quick: small batches")
    ap.add_argument("--device", help="portalsim bench --device")
    ap.add_argument("--dir", help="portalsim bench --dir: where the end-to-end runs write")
    ap.add_argument("--record")
    ap.add_argument("--check")
    ap.add_argument("--previous", help="the previous commit's portalsim, run in the same session")
    a = ap.parse_args()
    if a.json:
        with open(a.json) as f:
            report = json.load(f)
        a.repetitions = report.get("repetitions", a.repetitions)
    else:
        report = run(a.portalsim, a)
    previous = {p["key"]: p for p in run(a.previous, a)["paths"]} if a.previous else None
    rows, ratios = [], {}
    for p in report["paths"]:
        k, b, r, e = (rate(p[m]) for m in ("kernel", "loop", "reference", "end_to_end"))
        ratios[p["key"]] = k / b if k and b else None
        row = [p["title"], fmt(k), fmt(b), fmt(r), fmt(e), ratio(k, b), ratio(k, r, "%.0fx")]
        if previous is not None:
            row.append(fmt(rate(previous.get(p["key"], {}).get("kernel"))))
        rows.append("| " + " | ".join(row) + " |")
    head = ["path", "kernel", "baseline", "fp64 reference", "end to end", "kernel / baseline", "kernel / reference"]
    if previous is not None:
        head.append("previous build's kernel")
    print("| " + " | ".join(head) + " |")
    print("|" + "---|" * len(head))
    print("\n".join(rows))
    load = report["host"]["load_average"]
    print("\nMedians of %d runs of %s bench%s on %s, %s, load average %.1f." %
          (a.repetitions, a.json or a.portalsim, " and of " + a.previous + " bench" if a.previous else "",
           report["device"]["name"], report["date"], load[0]))
    if a.record:
        with open(a.record, "w") as f:
            json.dump({p: r for p, r in ratios.items() if r}, f, indent=2)  # paths without a loop: none
            f.write("\n")
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
