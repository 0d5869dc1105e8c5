#!/usr/bin/env python3
"""ctest tensors.python: data.h5 read from Python, and a CNN that learns from it.

    tensors_check.py PORTALSIM WORKDIR

Generates a small balanced gun set with --format h5, checks every dataset's shape and
dtype and the attributes with h5py, reads items through portalsim.torch.H5Dataset, and
runs tools/train_example.py on it: fails if the file cannot be read or if the model's
held-out accuracy is not clearly above chance. Also checks a randomised set's transforms
(the loader's transforms() against scenarios.csv) and an annotated set's mask targets.
"""
import csv
import json
import pathlib
import shutil
import subprocess
import sys

import h5py
import numpy as np
import torch

from portalsim.torch import H5Dataset

ROOT = pathlib.Path(__file__).resolve().parent.parent

N = 1000


def expect(cond, msg):
    if not cond:
        raise AssertionError(msg)


def main():
    portalsim, work = sys.argv[1], pathlib.Path(sys.argv[2])
    shutil.rmtree(work, ignore_errors=True)
    work.mkdir(parents=True)
    out = work / "gunset"
    subprocess.run([portalsim, "generate", "--count", str(N), "--seed", "1", "--rule", "gun", "--balance",
                    "--what", "both", "--format", "h5", "--compress", "--out", str(out), "--quiet"], check=True)
    manifest = json.loads((out / "manifest.json").read_text())
    with h5py.File(out / "data.h5", "r") as f:
        want = {"upper": ((N, 200, 200), np.uint8), "lower": ((N, 200, 200), np.uint8),
                "ir": ((N, 200, 100, 3), np.uint8), "ir_index": ((N, 200, 100), np.uint8),
                "metal": ((N, 19), np.uint8), "label": ((N,), np.uint8), "subject": ((N,), np.uint8),
                "region_object": ((N, 13), np.int16), "region_orientation": ((N, 13), np.int16),
                "region_label": ((N, 13), np.uint8)}
        for name, (shape, dtype) in want.items():
            expect(name in f, f"data.h5: no dataset {name}")
            expect(f[name].shape == shape, f"data.h5: {name} has shape {f[name].shape}, expected {shape}")
            expect(f[name].dtype == dtype, f"data.h5: {name} is {f[name].dtype}, expected {dtype}")
            expect(f[name].chunks[0] == 64, f"data.h5: {name} is chunked {f[name].chunks}, expected 64 along N")
            expect(f[name].compression == "gzip", f"data.h5: {name} is not gzip-compressed under --compress")
        feats = f["features"]
        expect(feats.dtype == np.float32 and feats.shape[0] == N, f"data.h5: features is {feats.dtype} {feats.shape}")
        expect(len(feats.attrs["columns"]) == feats.shape[1], "data.h5: features' column names do not match")
        expect(f.attrs["portalsim"] == manifest["portalsim"], "data.h5: attribute portalsim differs from manifest")
        expect(f.attrs["catalogue_hash"] == manifest["catalogue"]["hash"], "data.h5: catalogue_hash differs")
        expect(json.loads(f.attrs["spec"]) == manifest["spec"], "data.h5: attribute spec differs from the manifest")
        expect(list(f.attrs["class_names"]) == ["negative", "positive"], "data.h5: class_names")
        expect(sorted(f.attrs["datasets"]) == sorted(f.keys()), "data.h5: attribute datasets does not list them")
        expect(len(f.attrs["region_names"]) == 13, "data.h5: region_names")
        drawings = list(f.attrs["object_drawings"])
        expect(len(drawings) == len(f.attrs["object_names"]), "data.h5: object_drawings and object_names differ")
        obj, ori = f["region_object"][:], f["region_orientation"][:]
        expect(((obj < 0) == (ori < 0)).all(), "data.h5: region_orientation set where no object is")
        for o, d in zip(obj[obj >= 0], ori[obj >= 0]):
            expect(d < max(1, len(drawings[o].split(","))), f"data.h5: drawing {d} of object {o} ({drawings[o]})")
        label = f["label"][:]
        expect(label.sum() == N // 2, f"data.h5: --balance gave {label.sum()} threats of {N}")
        expect((f["region_label"][:].max(axis=1) == label).all(), "data.h5: label is not 'any region is a threat'")
        expect((f["subject"][:] >= 1).all(), "data.h5: subject numbers are 1-based")
        expect((f["ir"][:5] > 0).any() and (f["upper"][:5] > 0).any(), "data.h5: images are all zero")

    ds = H5Dataset(out / "data.h5", views=("upper", "lower"))
    x, y = ds[3]
    expect(tuple(x.shape) == (2, 200, 200) and float(x.max()) <= 1.0, f"dataset item has shape {tuple(x.shape)}")
    expect(int(y) == int(label[3]), "dataset label differs from the file's")
    ir = H5Dataset(out / "data.h5", views=("ir",), target="region_label")
    x, y = ir[0]
    expect(tuple(x.shape) == (3, 200, 100) and tuple(y.shape) == (13,), f"ir item {tuple(x.shape)}, {tuple(y.shape)}")

    expect(not ds.has_transforms, "a set without --rotate/--scale/--flip claims transforms")

    # Randomised objects: the transforms in data.h5 are scenarios.csv's numbers, exactly.
    rnd = work / "randomised"
    subprocess.run([portalsim, "generate", "--count", "60", "--seed", "4", "--objects", "1..4", "--rotate", "-30..30",
                    "--scale", "0.8..1.2", "--flip", "on", "--what", "images", "--format", "h5", "--out", str(rnd),
                    "--quiet"], check=True)
    with h5py.File(rnd / "data.h5", "r") as f:
        for name, dtype in (("region_rotation", np.float64), ("region_scale", np.float64), ("region_flip", np.uint8)):
            expect(f[name].shape == (60, 13) and f[name].dtype == dtype, f"data.h5: {name} is {f[name].dtype} "
                   f"{f[name].shape}, expected {np.dtype(dtype)} (60, 13)")
    tds = H5Dataset(rnd / "data.h5", views=("upper", "lower"))
    expect(tds.has_transforms, "the loader does not see the transforms")
    with open(rnd / "scenarios.csv") as fh:
        rows = list(csv.DictReader(fh))
    checked = 0
    for i, row in enumerate(rows):
        t = tds.transforms(i)
        for r in range(13):
            n = str(r + 1)
            if row["region" + n] == "none":
                expect(t["object"][r] == -1 and t["rotation"][r] == 0 and t["scale"][r] == 1 and t["flip"][r] == 0,
                       f"scenario {i} region {n}: an empty region is not the identity transform")
                continue
            got = (float(t["rotation"][r]), float(t["scale"][r]), str(int(t["flip"][r])))
            want = (float(row["rotation" + n]), float(row["scale" + n]), row["flip" + n])
            expect(got == want, f"scenario {i} region {n}: data.h5 has {got}, scenarios.csv {want}")
            checked += 1
    expect(checked >= 60, f"only {checked} objects in 60 scenarios of 1..4 objects")

    # Mask targets: a small annotated set; the loader's masks and boxes are annotations.json's.
    ann = work / "annotated"
    subprocess.run([portalsim, "generate", "--count", "40", "--seed", "3", "--objects", "2..5", "--what", "images",
                    "--format", "h5", "--annotations", "--out", str(ann), "--quiet"], check=True)
    seg = H5Dataset(ann / "data.h5", views=("upper", "lower"), target="mask")
    coco = json.loads((ann / "annotations.json").read_text())
    by_image = {}
    for a in coco["annotations"]:
        by_image.setdefault(a["image_id"], {})[a["region"]] = tuple(a["bbox"])
    views = [im for im in coco["images"] if im["view"] in ("upper", "lower")]
    expect(len(views) == 2 * 40, f"annotations.json has {len(views)} upper/lower images, expected 80")
    seen = 0
    for im in views:
        x, m = seg[im["scenario"]]
        expect(tuple(m.shape) == (2, 200, 200) and m.dtype == torch.int64, f"mask target {tuple(m.shape)} {m.dtype}")
        got = H5Dataset.boxes(m[("upper", "lower").index(im["view"])].numpy())
        expect(got == by_image.get(im["id"], {}),
               f"scenario {im['scenario']} view {im['view']}: loader boxes {got}, COCO {by_image.get(im['id'], {})}")
        seen += len(got)
    expect(seen > 40, f"only {seen} boxes in 40 scenarios of 2..5 objects")

    r = subprocess.run([sys.executable, str(ROOT / "tools" / "train_example.py"), str(out / "data.h5"),
                        "--steps", "250"], capture_output=True, text=True)
    print(r.stdout, r.stderr, end="")
    expect(r.returncode == 0, "train_example.py: the model did not learn (accuracy at chance) or failed")
    shutil.rmtree(work, ignore_errors=True)
    print("tensors.python: ok")


if __name__ == "__main__":
    main()
