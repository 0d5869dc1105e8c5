#!/usr/bin/python3
"""The front-and-back portal's views (scenarios/portal-front-back.toml) with its regions.

    plot_portal_views.py PORTALSIM OUT.png

One scenario with objects on the front and the back, simulated by both models; each view
with its regions' rectangles and numbers, as the catalogue declares them. The catalogue is
read with tomllib: the rectangles drawn are the file's, not a copy.
"""
import os
import subprocess
import sys
import tempfile
import tomllib

import matplotlib

matplotlib.use("Agg")
import matplotlib.image as mpimg  # noqa: E402
import matplotlib.patches as patches  # noqa: E402
import matplotlib.pyplot as plt  # noqa: E402

CATALOGUE = os.path.join(os.path.dirname(__file__), "..", "scenarios", "portal-front-back.toml")
# Regions 1..19: a gun at the right chest (1), a rod at the centre hip (8), a phone on the
# upper back (14), a plate at the seat (17) and the gun's vertical drawing at the back of the
# left knee (19).
OBJECTS = ["gun", "none", "none", "none", "none", "none", "none", "iron-rod", "none", "none", "none", "none", "none",
           "mobile-phone", "none", "none", "metal-plate", "none", "gun:v"]


def main():
    portalsim, out = sys.argv[1], sys.argv[2]
    with open(CATALOGUE, "rb") as f:
        cat = tomllib.load(f)
    views = [v["name"] for v in cat["views"]]
    fig, axes = plt.subplots(2, len(views), figsize=(2.3 * len(views), 5.6),
                             gridspec_kw={"width_ratios": [v["size"][0] for v in cat["views"]]})
    with tempfile.TemporaryDirectory() as work:
        for row, model in enumerate(["thesis", "physics"]):
            folder = os.path.join(work, model)
            subprocess.run([portalsim, "simulate", "--catalogue", CATALOGUE, "--model", model, "--out", folder]
                           + OBJECTS, check=True, stdout=subprocess.DEVNULL)
            for col, view in enumerate(cat["views"]):
                ax = axes[row][col]
                img = mpimg.imread(os.path.join(folder, view["name"] + ".png"))
                ax.imshow(img, cmap="gray", vmin=0, vmax=1, interpolation="nearest")
                for k, region in enumerate(cat["regions"]):
                    rect = region["rects"].get(view["name"])
                    if rect is None:
                        continue
                    x, y, w, h = rect
                    ax.add_patch(patches.Rectangle((x - 0.5, y - 0.5), w, h, fill=False, lw=0.7, ec="#2a9df4"))
                    ax.text(x + 1, y + 1, str(k + 1), color="#2a9df4", fontsize=6, va="top")
                side = view.get("side", "front")
                ax.set_title(f"{view['name']} ({view['camera']}, {side})" if row == 0 else "", fontsize=8)
                ax.set_xticks([])
                ax.set_yticks([])
            axes[row][0].set_ylabel(f"--model {model}", fontsize=8)
    fig.suptitle("scenarios/portal-front-back.toml: regions 1-13 on the front, 14-19 on the back "
                 "(a back view is mirrored)", fontsize=9)
    fig.tight_layout()
    fig.savefig(out, dpi=110)


if __name__ == "__main__":
    main()
