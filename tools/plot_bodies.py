#!/usr/bin/python3
"""Draws a contact sheet of random bodies (`--bodies random`): each body's MMW views and IR.

  /usr/bin/python3 tools/plot_bodies.py PORTALSIM OUT.png [--count 32] [--seed 1] [--model physics]
                                       [--clothing catalogue|random|none|shirt|sweater|jacket|coat]
                                       [-- GENERATE FLAGS...]

PORTALSIM is the built binary. The tool runs `portalsim generate --bodies random
--body-count COUNT --scenarios LIST --what images`, one listed scenario per body, each
carrying a few objects (a gun, a phone, a metal plate, a belt buckle, an iron rod by turns),
and draws for each body the two MMW views stacked (the whole body, floor at the bottom) and
the IR view beside them, titled with the body as scenarios.csv records it: sex, stature,
pose, and with --clothing other than the catalogue's, the outfit each drew
(docs/model/clothing.md). Flags after `--` go to `generate` as they are: knobs drawn per
scenario (`-- --mmw-raw 14x14,28x28,40x40 --netd 1..4 --illumination 285..305`) add each
body's draws to its title (docs/model/drawn-knobs.md). Needs Debian's python3-matplotlib
and python3-numpy.
"""
import argparse
import csv
import math
import pathlib
import subprocess
import sys
import tempfile

import matplotlib

matplotlib.use("Agg")
import matplotlib.image as mpimg  # noqa: E402
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

REGIONS = 13
# The drawn knobs' columns of scenarios.csv a title shows, each as a format of its value.
DRAWN = [("netd", "NETD {:.1f} K"), ("frames", "{:.0f} fr"), ("illumination", "{:.0f} K room"),
         ("worn_minutes", "worn {:.0f} min"), ("ir_netd", "IR {:.2f} K"),
         ("clothing_folds", "folds {:.2f}")]

# Objects by turns: (region number, object) pairs for body k, k modulo the list.
CARRIED = [
    [(2, "gun")],
    [(4, "mobile-phone"), (10, "iron-rod")],
    [(8, "metal-plate")],
    [(5, "belt-buckle"), (1, "gun")],
    [],
]


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("portalsim")
    ap.add_argument("out")
    ap.add_argument("--count", type=int, default=32)
    ap.add_argument("--seed", default="1")
    ap.add_argument("--model", default="physics")
    ap.add_argument("--columns", type=int, default=8)
    ap.add_argument("--clothing", default="catalogue")
    argv = sys.argv[1:]
    cut = argv.index("--") if "--" in argv else len(argv)
    a = ap.parse_args(argv[:cut])
    extra = argv[cut + 1:]  # flags for portalsim generate
    with tempfile.TemporaryDirectory() as tmp:
        tmp = pathlib.Path(tmp)
        listing = tmp / "list.csv"
        rows = ["subject," + ",".join(f"region{r}" for r in range(1, REGIONS + 1))]
        for k in range(a.count):
            objects = ["none"] * REGIONS
            for region, name in CARRIED[k % len(CARRIED)]:
                objects[region - 1] = name
            rows.append(f"{k + 1}," + ",".join(objects))
        listing.write_text("\n".join(rows) + "\n")
        out = tmp / "run"
        subprocess.run([a.portalsim, "generate", "--bodies", "random", "--body-count", str(a.count), "--seed", a.seed,
                        "--model", a.model, "--clothing", a.clothing, "--scenarios", str(listing), "--what", "images",
                        "--quiet", *extra, "--out",
                        str(out)], check=True, stdout=subprocess.DEVNULL)
        with open(out / "scenarios.csv", newline="") as f:
            bodies = list(csv.DictReader(f))
        cols = a.columns
        lines = math.ceil(a.count / cols)
        fig, axes = plt.subplots(lines, 2 * cols, squeeze=False, figsize=(1.55 * 2 * cols, 3.25 * lines),
                                 gridspec_kw={"wspace": 0.03, "hspace": 0.28})
        for ax in axes.flat:
            ax.set_axis_off()
        for k, body in enumerate(bodies):
            folder = out / "images" / f"{int(body['index']):08d}"
            upper = mpimg.imread(folder / "upper.png")
            lower = mpimg.imread(folder / "lower.png")
            ir = mpimg.imread(folder / "ir.png")
            r, c = divmod(k, cols)
            axes[r, 2 * c].imshow(np.vstack([upper, lower]), cmap="gray", vmin=0, vmax=1)
            axes[r, 2 * c + 1].imshow(ir)
            sex = "F" if body["sex"] == "female" else "M"
            title = (f"{k + 1}: {sex} {float(body['stature_mm']) / 1000:.2f} m\n{body['pose']}, "
                     f"e {float(body['skin_emissivity']):.2f}")
            if "clothing" in body:  # "shirt:cotton+sweater:wool" -> "cotton shirt, wool sweater"
                layers = [p.split(":") for p in body["clothing"].split("+")] if body["clothing"] != "none" else []
                title += "\n" + (", ".join(f"{f} {g}" for g, f in layers) or "no clothing")
            if "mmw_raw_width" in body:
                title += f"\nraw {body['mmw_raw_width']}x{body['mmw_raw_height']}"
            drawn = [fmt.format(float(body[key])) for key, fmt in DRAWN if key in body]
            for k0 in range(0, len(drawn), 2):
                title += "\n" + ", ".join(drawn[k0:k0 + 2])
            small = a.clothing != "catalogue" or extra
            axes[r, 2 * c].set_title(title, fontsize=6 if small else 7, loc="left")
        dressed = ("" if a.clothing == "catalogue" else f", --clothing {a.clothing}") + "".join(
            f" {x}" for x in extra)
        fig.suptitle(f"{a.count} random bodies (--bodies random, seed {a.seed}, --model {a.model}{dressed}): "
                     "MMW upper over lower, and IR", fontsize=11)
        fig.savefig(a.out, dpi=64, bbox_inches="tight")


if __name__ == "__main__":
    main()
