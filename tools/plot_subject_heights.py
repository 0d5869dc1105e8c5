#!/usr/bin/python3
"""Draws one scenario on one subject at three heights (Subject::height), side by side.

  /usr/bin/python3 tools/plot_subject_heights.py PORTALSIM OUT.png [--heights 0.85,1,1.15]

PORTALSIM is the built binary. The tool writes, per height, a copy of
scenarios/catalogue.toml whose first subject has `height = H`, runs `portalsim generate
--scenarios LIST --what images --annotations` on it with one listed scenario (a gun, a
mobile phone, an iron rod, a metal plate and a belt buckle on subject 1), and draws the two
MMW views stacked (upper over lower: the whole body, floor at the bottom) and the IR view
beside them, each with its COCO boxes. The dashed line is the upper view's bottom edge.
Needs Debian's python3-matplotlib and python3-numpy.
"""
import argparse
import json
import pathlib
import re
import subprocess
import tempfile

import matplotlib

matplotlib.use("Agg")
import matplotlib.image as mpimg  # noqa: E402
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

OBJECTS = ["none", "gun", "none", "mobile-phone", "none", "belt-buckle", "none", "metal-plate", "none", "iron-rod"] + \
    ["none"] * 3
CATALOGUE = pathlib.Path(__file__).resolve().parent.parent / "scenarios" / "catalogue.toml"


def with_height(text, height):
    """The catalogue with its first [[subjects]] table given `height`."""
    at = text.index("[[subjects]]")
    head, rest = text[:at], text[at:]
    rest, n = re.subn(r"^(build = .*)$", rf"\1\nheight = {height}", rest, count=1, flags=re.M)
    if n != 1:
        raise SystemExit("the catalogue's first subject has no build line")
    return head + rest


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("portalsim")
    ap.add_argument("out")
    ap.add_argument("--heights", default="0.85,1,1.15")
    a = ap.parse_args()
    heights = [float(h) for h in a.heights.split(",")]
    with tempfile.TemporaryDirectory() as tmp:
        tmp = pathlib.Path(tmp)
        listing = tmp / "list.csv"
        listing.write_text("subject," + ",".join(f"region{r}" for r in range(1, 14)) + "\n1," + ",".join(OBJECTS) +
                           "\n")
        fig, axes = plt.subplots(1, 2 * len(heights), figsize=(3.2 * len(heights), 3.9),
                                 gridspec_kw={"width_ratios": [1, 1] * len(heights), "wspace": 0.05})
        for k, height in enumerate(heights):
            cat = tmp / f"catalogue{k}.toml"
            cat.write_text(with_height(CATALOGUE.read_text(), height))
            out = tmp / f"h{k}"
            subprocess.run([a.portalsim, "generate", "--catalogue", str(cat), "--scenarios", str(listing), "--what",
                            "images", "--annotations", "--quiet", "--out", str(out)], check=True,
                           stdout=subprocess.DEVNULL)
            coco = json.loads((out / "annotations.json").read_text())
            images = {im["view"]: im for im in coco["images"]}
            boxes = {v: [ann["bbox"] for ann in coco["annotations"] if ann["image_id"] == images[v]["id"]]
                     for v in images}
            upper = mpimg.imread(out / images["upper"]["file_name"])
            lower = mpimg.imread(out / images["lower"]["file_name"])
            mmw = np.vstack([upper, lower])
            ax = axes[2 * k]
            ax.imshow(mmw, cmap="gray", vmin=0, vmax=1)
            for view, dy in (("upper", 0), ("lower", upper.shape[0])):
                for x, y, w, h in boxes[view]:
                    ax.add_patch(plt.Rectangle((x - 0.5, y + dy - 0.5), w, h, fill=False, color="tab:orange", lw=1))
            ax.axhline(upper.shape[0] - 0.5, color="tab:cyan", lw=0.8, ls="--")
            ax.set_title(f"height {height:g}: MMW", fontsize=9)
            ax = axes[2 * k + 1]
            ax.imshow(mpimg.imread(out / images["ir"]["file_name"]))
            for x, y, w, h in boxes["ir"]:
                ax.add_patch(plt.Rectangle((x - 0.5, y - 0.5), w, h, fill=False, color="white", lw=0.8))
            ax.set_title("IR", fontsize=9)
            for ax in axes[2 * k:2 * k + 2]:
                ax.set_xticks([])
                ax.set_yticks([])
        fig.savefig(a.out, dpi=110, bbox_inches="tight", pad_inches=0.05)


if __name__ == "__main__":
    main()
