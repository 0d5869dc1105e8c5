#!/usr/bin/python3
"""Draws one scenario under portalsim's randomised-object knobs, side by side.

  /usr/bin/python3 tools/plot_randomised_objects.py PORTALSIM OUT.png [--seed N]

PORTALSIM is the built binary. The tool writes a one-scenario list (a gun, a metal plate,
a mobile phone, a rod and a belt buckle on subject 1), runs `portalsim generate --scenarios
LIST --what images --annotations` once per panel (today's placement, --rotate 180,
--scale 0.6..1.6, --flip on, and all three with --jitter 6), and draws the upper MMW view of
each (the torso) with its COCO boxes and, in the title, what scenarios.csv recorded for the gun.
Needs Debian's python3-matplotlib and python3-numpy.
"""
import argparse
import csv
import json
import pathlib
import subprocess
import tempfile

import matplotlib

matplotlib.use("Agg")
import matplotlib.image as mpimg  # noqa: E402
import matplotlib.pyplot as plt  # noqa: E402

OBJECTS = ["gun", "metal-plate", "mobile-phone", "none", "iron-rod", "belt-buckle"] + ["none"] * 7
PANELS = [
    ("today", []),
    ("--rotate 180", ["--rotate", "180"]),
    ("--scale 0.6..1.6", ["--scale", "0.6..1.6"]),
    ("--flip on", ["--flip", "on"]),
    ("all three, --jitter 6", ["--rotate", "180", "--scale", "0.6..1.6", "--flip", "on", "--jitter", "6"]),
]


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("portalsim")
    ap.add_argument("out")
    ap.add_argument("--seed", default="11")
    a = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        tmp = pathlib.Path(tmp)
        listing = tmp / "list.csv"
        listing.write_text("subject," + ",".join(f"region{r}" for r in range(1, 14)) + "\n1," + ",".join(OBJECTS) +
                           "\n")
        fig, axes = plt.subplots(1, len(PANELS), figsize=(3.2 * len(PANELS), 3.4))
        for k, (title, knobs) in enumerate(PANELS):
            out = tmp / f"p{k}"
            subprocess.run([a.portalsim, "generate", "--scenarios", str(listing), "--seed", a.seed, "--what", "images",
                            "--annotations", "--quiet", "--out", str(out)] + knobs, check=True, stdout=subprocess.DEVNULL)
            coco = json.loads((out / "annotations.json").read_text())
            upper = next(im for im in coco["images"] if im["view"] == "upper")
            image = mpimg.imread(out / upper["file_name"])
            upper = upper["id"]
            ax = axes[k]
            ax.imshow(image, cmap="gray", vmin=0, vmax=1)
            for ann in coco["annotations"]:
                if ann["image_id"] != upper:
                    continue
                x, y, w, h = ann["bbox"]
                ax.add_patch(plt.Rectangle((x - 0.5, y - 0.5), w, h, fill=False, color="tab:orange", lw=1))
            row = next(csv.DictReader((out / "scenarios.csv").open()))
            if "rotation1" in row:
                title += f"\ngun: {float(row['rotation1']):.1f}°, x{float(row['scale1']):.2f}"
                title += ", mirrored" if row["flip1"] == "1" else ""
            ax.set_title(title, fontsize=9)
            ax.set_xlim(20, 180)  # the torso, where the objects are
            ax.set_ylim(168, 35)
            ax.set_xticks([])
            ax.set_yticks([])
        fig.tight_layout()
        fig.savefig(a.out, dpi=110)


if __name__ == "__main__":
    main()
