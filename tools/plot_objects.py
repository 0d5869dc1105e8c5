#!/usr/bin/python3
"""Draws every catalogue object as the cameras see it: alone on subject 1, both cameras.

  /usr/bin/python3 tools/plot_objects.py PORTALSIM OUT.png [--model physics] [--region 2] [--seed 3]

PORTALSIM is the built binary. The tool reads the objects from `portalsim catalogue`, lists
one scenario per object (subject 1, the object alone in REGION, its first drawing), runs
`portalsim generate --scenarios LIST --what images`, and draws for each object
the upper MMW view and the IR view's upper half side by side, titled with its name, class
and metal category. Objects outside the default pool are marked with a ring. Needs
Debian's python3-matplotlib and python3-numpy.
"""
import argparse
import math
import pathlib
import subprocess
import tempfile

import matplotlib

matplotlib.use("Agg")
import matplotlib.image as mpimg  # noqa: E402
import matplotlib.pyplot as plt  # noqa: E402

REGIONS = 13


def catalogue_objects(portalsim):
    """(name, metal category, class, in the default pool) per object, in catalogue order."""
    text = subprocess.run([portalsim, "catalogue"], check=True, capture_output=True, text=True).stdout
    rows, inside = [], False
    for line in text.splitlines():
        if line.startswith("objects ("):
            inside = True
            continue
        if inside and not line.strip():
            break
        if inside:
            default = line[2] == "*"
            words = line[4:].split()
            if words[1].startswith("["):
                words.pop(1)
            rows.append((words[0], words[1], words[2], default))
    return rows


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("portalsim")
    ap.add_argument("out")
    ap.add_argument("--model", default="physics")
    ap.add_argument("--region", type=int, default=2)
    ap.add_argument("--seed", default="3")
    ap.add_argument("--columns", type=int, default=8)
    a = ap.parse_args()
    objects = catalogue_objects(a.portalsim)
    with tempfile.TemporaryDirectory() as tmp:
        tmp = pathlib.Path(tmp)
        listing = tmp / "list.csv"
        rows = ["subject," + ",".join(f"region{r}" for r in range(1, REGIONS + 1))]
        for name, _, _, _ in objects:
            cells = ["none"] * REGIONS
            cells[a.region - 1] = name
            rows.append("1," + ",".join(cells))
        listing.write_text("\n".join(rows) + "\n")
        out = tmp / "run"
        subprocess.run([a.portalsim, "generate", "--model", a.model, "--seed", a.seed, "--scenarios", str(listing),
                        "--what", "images", "--quiet", "--out", str(out)], check=True, stdout=subprocess.DEVNULL)
        cols = a.columns
        lines = math.ceil(len(objects) / cols)
        fig, axes = plt.subplots(lines, 2 * cols, figsize=(1.6 * 2 * cols, 1.95 * lines),
                                 gridspec_kw={"wspace": 0.03, "hspace": 0.32})
        for ax in axes.flat:
            ax.set_axis_off()
        for k, (name, metal, klass, default) in enumerate(objects):
            folder = out / "images" / f"{k:08d}"
            upper = mpimg.imread(folder / "upper.png")
            ir = mpimg.imread(folder / "ir.png")
            r, c = divmod(k, cols)
            axes[r, 2 * c].imshow(upper, cmap="gray", vmin=0, vmax=1)
            axes[r, 2 * c + 1].imshow(ir[: ir.shape[0] // 2])
            mark = "" if default else "\u25cb "
            axes[r, 2 * c].set_title(f"{mark}{name}\n{klass}, metal {metal}", fontsize=7.5, loc="left")
        fig.suptitle(f"Every catalogue object alone in region {a.region} of subject 1, --model {a.model}: MMW upper "
                     "view and IR upper half (\u25cb: outside the default pool)", fontsize=10)
        fig.savefig(a.out, dpi=90, bbox_inches="tight")


if __name__ == "__main__":
    main()
