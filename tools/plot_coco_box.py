#!/usr/bin/python3
"""Draws the COCO boxes of one MMW image of a portalsim data set over the image.

  /usr/bin/python3 tools/plot_coco_box.py DATASET OUT.png [--scenario N] [--view upper]

DATASET is the folder `portalsim generate --what images --annotations` wrote (image
folders, annotations.json). Left: the image with each annotation's box and category; right:
its instance mask decoded from the COCO RLE (the same pixels as mask_<view>.png).
Needs Debian's python3-matplotlib and python3-numpy.
"""
import argparse
import json
import pathlib

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402


def decode_rle(seg):
    """COCO's uncompressed RLE: run lengths over the column-major pixels, 0s first."""
    h, w = seg["size"]
    flat = np.zeros(h * w, dtype=np.uint8)
    at, on = 0, False
    for n in seg["counts"]:
        if on:
            flat[at:at + n] = 1
        at += n
        on = not on
    return flat.reshape((w, h)).T


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("dataset")
    ap.add_argument("out")
    ap.add_argument("--scenario", type=int, default=None, help="default: the one with the most boxes")
    ap.add_argument("--view", default="upper")
    a = ap.parse_args()
    root = pathlib.Path(a.dataset)
    coco = json.loads((root / "annotations.json").read_text())
    names = {c["id"]: c["name"] for c in coco["categories"]}
    images = [im for im in coco["images"] if im["view"] == a.view]
    by_image = {}
    for ann in coco["annotations"]:
        by_image.setdefault(ann["image_id"], []).append(ann)
    if a.scenario is None:
        image = max(images, key=lambda im: (len(by_image.get(im["id"], [])), -im["scenario"]))
    else:
        image = next(im for im in images if im["scenario"] == a.scenario)
    anns = by_image.get(image["id"], [])
    pixels = plt.imread(root / image["file_name"])
    fig, (left, right) = plt.subplots(1, 2, figsize=(8.4, 4.4))
    left.imshow(pixels, cmap="gray", vmin=0, vmax=1)
    label = np.zeros((image["height"], image["width"]), dtype=np.uint8)
    colours = plt.get_cmap("tab10")
    for k, ann in enumerate(anns):
        x, y, w, h = ann["bbox"]
        c = colours(k % 10)
        # bbox is [x, y, w, h] over pixel indices: the box's edges are half a pixel out.
        left.add_patch(plt.Rectangle((x - 0.5, y - 0.5), w, h, fill=False, edgecolor=c, linewidth=1.6))
        left.text(x - 0.5, y - 3, f'{names[ann["category_id"]]} (region {ann["region"]})', color="white", fontsize=7,
                  bbox=dict(facecolor=c, alpha=0.85, pad=1, linewidth=0))
        label[decode_rle(ann["segmentation"]) == 1] = k + 1
    left.set_title(f'{image["file_name"]}: COCO boxes', fontsize=9)
    right.imshow(np.ma.masked_equal(label, 0), cmap=matplotlib.colors.ListedColormap(
        [colours(k % 10) for k in range(max(1, len(anns)))]), vmin=1, vmax=max(1, len(anns)), interpolation="nearest")
    right.set_facecolor("black")
    right.set_xlim(-0.5, image["width"] - 0.5)
    right.set_ylim(image["height"] - 0.5, -0.5)
    right.set_title("instance masks (decoded RLE)", fontsize=9)
    for ax in (left, right):
        ax.set_xticks([])
        ax.set_yticks([])
    fig.tight_layout()
    fig.savefig(a.out, dpi=100)


if __name__ == "__main__":
    main()
