#!/usr/bin/env python3
"""How thesis case 2's accuracies under --model physics depend on the camera's frames and
its NETD: docs/physics_sensitivity.png and a table on stdout.

    /usr/bin/python3 tools/physics_sensitivity.py build/portalsim docs/physics_sensitivity.png [--count 300] [--mlp]

Each point is tools/real_camera_table.py's protocol (case 2, WEKA 10-fold CV, -s 1) on
`--count` scenarios of the physics model at its defaults but for the knob varied: --frames
at the default NETD, then --netd at the default frames. J48 and SMO on both feature sets
(with --mlp also MultilayerPerceptron on region means: minutes a point; on 819 attributes
it takes hours). The real
camera's figures (thesis Tables 6.1 and 6.2) are drawn as bands of their 95% interval.
"""
import argparse
import sys
import tempfile
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parent))
import real_camera_table as rct  # noqa: E402

RUNS = [("regions", "j48"), ("regions", "svm"), ("blocks", "j48"), ("blocks", "svm")]


def accuracies(portalsim, folder, count, knobs, mlp):
    folder.mkdir(parents=True, exist_ok=True)
    arff = rct.generate(portalsim, folder / "data", "physics", count, 25, knobs)
    sets = rct.split(arff, folder)
    runs = RUNS + ([("regions", "mlp")] if mlp else [])
    return {(fs, c): rct.weka(c, sets[fs][0], folder / f"{fs}.{c}.txt") for fs, c in runs}


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("portalsim")
    ap.add_argument("png")
    ap.add_argument("--count", type=int, default=300)
    ap.add_argument("--frames", default="1,4,10,32")
    ap.add_argument("--netd", default="0,1.5,3,6")
    ap.add_argument("--mlp", action="store_true", help="also MultilayerPerceptron on region means (slow)")
    a = ap.parse_args()
    work = Path(tempfile.mkdtemp(prefix="sensitivity_"))
    sweeps = {"frames": [int(v) for v in a.frames.split(",")], "netd": [float(v) for v in a.netd.split(",")]}
    results = {}
    for knob, values in sweeps.items():
        for v in values:
            results[(knob, v)] = accuracies(a.portalsim, work / f"{knob}{v}", a.count, [f"{knob}={v}"], a.mlp)
            print(knob, v, " ".join(f"{fs}/{c} {p:.1f}" for (fs, c), p in results[(knob, v)].items()), flush=True)
    fig, axes = plt.subplots(2, 2, figsize=(11, 8), sharey=True)
    for col, (knob, values) in enumerate(sweeps.items()):
        for row, fs in enumerate(["regions", "blocks"]):
            ax = axes[row, col]
            for k, c in enumerate(["j48", "mlp", "svm"]):
                if (fs, c) not in results[(knob, values[0])]:
                    continue
                real, half = rct.REAL[(fs, c)], rct.interval(rct.REAL[(fs, c)], rct.REAL_PROFILES)
                ax.axhspan(real - half, real + half, color=f"C{k}", alpha=0.12)
                ax.plot(values, [results[(knob, v)][(fs, c)] for v in values], "o-", color=f"C{k}",
                        label=f"{rct.NAMES[c]} (band: real camera +- 95%)")
            if knob == "frames":
                ax.set_xscale("log", base=2)
            ax.set_xlabel("--frames (NETD 3 K)" if knob == "frames" else "--netd, K (default frames)")
            ax.set_ylabel("10-fold accuracy, %")
            ax.set_title(("region means + zones" if fs == "regions" else "10x10 block means + zones") +
                         f", case 2, {a.count} scenarios", fontsize=10)
            ax.grid(alpha=0.3)
            ax.legend(fontsize=8, loc="lower left")
    fig.suptitle("portalsim --model physics: thesis case 2 accuracy against the camera's frames and NETD")
    fig.tight_layout()
    fig.savefig(a.png, dpi=80)


if __name__ == "__main__":
    main()
