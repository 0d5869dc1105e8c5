#!/usr/bin/env python3
"""The README's pictures of the physics model, made from portalsim's own outputs.

    /usr/bin/python3 tools/physics_figures.py build/portalsim docs/

docs/models_side_by_side.png: one scenario (a gun at the right abdomen, a phone at the
left thigh) under --model thesis, --model physics, and physics without sensor noise
(--netd 0): upper, lower, IR and the metal detector's 19 zones on its two panels.
docs/physics_profile.png: one row across the gun through the physics chain, from
`simulate --stages`: apparent temperature, after the PSF, on the raw grid, with NETD, and
the displayed gray levels.
"""
import subprocess
import sys
import tempfile
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

OBJECTS = ["none", "none", "none", "gun", "none", "none", "none", "none", "mobile-phone"]


def simulate(portalsim, out, model, *knobs):
    subprocess.run([portalsim, "simulate", "--model", model, *knobs, "--stages", "--seed", "3", *OBJECTS, "--out",
                    str(out)], check=True, stdout=subprocess.DEVNULL)
    return out


def zones(folder):
    return [int(v) for v in (folder / "metal.txt").read_text().split(",")]


def side_by_side(rows, path):
    fig, axes = plt.subplots(len(rows), 4, figsize=(12, 3.2 * len(rows)),
                             gridspec_kw={"width_ratios": [1, 1, 0.55, 0.8]})
    for row, (name, folder) in enumerate(rows):
        for col, view in enumerate(["upper", "lower", "ir"]):
            ax = axes[row, col]
            img = plt.imread(folder / f"{view}.png")
            ax.imshow(img, cmap="gray" if img.ndim == 2 else None, vmin=0, vmax=1)
            ax.set_xticks([])
            ax.set_yticks([])
            ax.set_title(f"{name}: {view}", fontsize=10)
        ax = axes[row, 3]
        z = np.array(zones(folder))
        # Zones 1-9 on one panel (top to bottom), 10-19 on the other.
        for panel, (lo, hi, x) in enumerate([(0, 9, 0), (9, 19, 1)]):
            heights = np.linspace(0.95, 0.05, hi - lo)
            ax.barh(heights, 200 - z[lo:hi], height=0.08, left=x * 220, color="C%d" % panel)
            for h, v in zip(heights, z[lo:hi]):
                ax.text(x * 220 + 205, h, str(v), va="center", fontsize=6)
        ax.set_xlim(0, 450)
        ax.set_ylim(0, 1)
        ax.set_yticks([])
        ax.set_xticks([0, 220])
        ax.set_xticklabels(["panel A\n(200 - zone)", "panel B"], fontsize=7)
        ax.set_title(f"{name}: metal zones", fontsize=10)
    fig.suptitle("portalsim simulate [--model thesis|physics] none none none gun none none none none mobile-phone")
    fig.tight_layout()
    fig.savefig(path, dpi=90)


def profile(physics, path):
    stages = physics / "stages"
    y = 145  # the gun's row in the upper view (region 4)
    t = np.load(stages / "upper.1.radiometry.npy")
    blurred = np.load(stages / "upper.2.optics.npy")
    raw = np.load(stages / "upper.3.sample.npy")
    noisy = np.load(stages / "upper.4.netd.npy")
    shown = np.load(stages / "upper.6.mmw_display.npy")
    rw = raw.shape[1]
    r = int(y * raw.shape[0] / t.shape[0])
    edges = np.arange(rw + 1) * t.shape[1] / rw
    fig, ax = plt.subplots(figsize=(9, 4.2))
    x = np.arange(t.shape[1]) + 0.5
    ax.plot(x, t[y], label="apparent temperature (radiometry)", color="k", lw=1)
    ax.plot(x, blurred[y], label="after the PSF (optics)", color="C0")
    ax.stairs(raw[r], edges, label=f"raw grid, row {r} (sample)", color="C1", lw=1.5, baseline=None)
    ax.stairs(noisy[r], edges, label="with NETD (netd)", color="C3", lw=1, baseline=None)
    ax.set_ylim(285, 305)
    ax.set_xlabel("x, view pixels (upper view, row %d)" % y)
    ax.set_ylabel("kelvin")
    ax2 = ax.twinx()
    ax2.plot(x, shown[y], color="0.5", ls=":", label="displayed gray (mmw_display)")
    ax2.set_ylabel("gray level")
    h1, l1 = ax.get_legend_handles_labels()
    h2, l2 = ax2.get_legend_handles_labels()
    ax.legend(h1 + h2, l1 + l2, fontsize=7, loc="lower right")
    ax.set_title("A row across the gun through the physics MMW chain (simulate --stages)")
    fig.tight_layout()
    fig.savefig(path, dpi=90)


def main():
    portalsim, out = sys.argv[1], Path(sys.argv[2])
    out.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory() as tmp:
        thesis = simulate(portalsim, Path(tmp) / "thesis", "thesis")
        physics = simulate(portalsim, Path(tmp) / "physics", "physics")
        quiet = simulate(portalsim, Path(tmp) / "quiet", "physics", "--netd", "0")
        side_by_side([("thesis", thesis), ("physics", physics), ("physics, NETD 0", quiet)],
                     out / "models_side_by_side.png")
        profile(physics, out / "physics_profile.png")


if __name__ == "__main__":
    main()
