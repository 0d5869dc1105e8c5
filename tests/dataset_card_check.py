#!/usr/bin/env python3
"""ctest dataset_card.python: every folder generate writes describes itself.

    dataset_card_check.py PORTALSIM WORKDIR

For several output combinations (feature tables and image folders; data.h5 with
annotations and randomised objects; .npy tensors with annotations; features-only data.h5
under the physics model) it checks:
- croissant.json is JSON-LD (pyld expands it with its own context) in Croissant's
  vocabulary; every distribution entry names a file that exists (a FileSet's glob matches
  files) with the size it states; every file of the folder is described; every field's
  source exists: the CSV or ARFF column, the data.h5 dataset or the .npy tensor with its
  per-row shape, the JSON path in annotations.json; and every column, dataset and tensor
  has a field;
- README.md's YAML front matter holds what the manifest holds, and its command makes the
  same data set again, byte for byte;
- both files are byte-identical for another --batch and --threads, and for shards joined
  by merge.
"""
import fnmatch
import json
import os
import pathlib
import shlex
import shutil
import subprocess
import sys

import h5py
import numpy as np
import yaml
from pyld import jsonld

CR = "http://mlcommons.org/croissant/"
SC = "https://schema.org/"
CARD_FILES = ("README.md", "croissant.json")


def expect(cond, msg):
    if not cond:
        raise AssertionError(msg)


def generate(portalsim, out, args):
    subprocess.run([portalsim, "generate", *args, "--out", str(out), "--quiet"], check=True,
                   stdout=subprocess.DEVNULL)


def folder_files(d):
    """Every file under d (relative, '/'-separated), the run's state and the card aside."""
    out = []
    for root, dirs, files in os.walk(d):
        dirs[:] = [x for x in dirs if not x.startswith(".portalsim")]
        for f in files:
            rel = os.path.relpath(os.path.join(root, f), d).replace(os.sep, "/")
            if rel not in CARD_FILES and not rel.startswith(".portalsim"):
                out.append(rel)
    return sorted(out)


def json_path_values(doc, path):
    """$.array[*].key or $.array[*].key.sub: the key's value in every element (must exist)."""
    expect(path.startswith("$.") and "[*]." in path, f"unexpected jsonPath {path}")
    array, keys = path[2:].split("[*].")
    items = doc[array]
    expect(len(items) > 0, f"jsonPath {path}: {array} is empty")
    values = []
    for it in items:
        for k in keys.split("."):
            expect(isinstance(it, dict) and k in it, f"jsonPath {path}: an element of {array} has no {keys}")
            it = it[k]
        values.append(it)
    return values


def check_croissant(d, manifest):
    """Raises on anything croissant.json says that is not so, or leaves out."""
    c = json.loads((d / "croissant.json").read_text())
    expect(c["@context"]["cr"] == CR and c["@context"]["@vocab"] == SC, "croissant.json: not Croissant's vocabulary")
    expect(c["@type"] == "sc:Dataset" and c["conformsTo"] == CR + "1.0", "croissant.json: not a Croissant 1.0 Dataset")
    expanded = jsonld.expand(c)
    expect(len(expanded) == 1 and SC + "Dataset" in expanded[0]["@type"], "croissant.json: JSON-LD: no sc:Dataset")
    expect(CR + "recordSet" in expanded[0] and SC + "distribution" in expanded[0],
           "croissant.json: JSON-LD: recordSet or distribution did not expand into Croissant's terms")
    count = manifest["count"]
    files = folder_files(d)
    objects, sets, covered = {}, {}, set()
    for e in c["distribution"]:
        if e["@type"] == "cr:FileObject":
            p = d / e["contentUrl"]
            expect(p.is_file(), f"croissant.json: distribution names {e['contentUrl']}, which does not exist")
            if "contentSize" in e:
                expect(e["contentSize"] == f"{p.stat().st_size} B", f"croissant.json: {e['contentUrl']}: wrong size")
            objects[e["@id"]] = e["contentUrl"]
            covered.add(e["contentUrl"])
        else:
            expect(e["@type"] == "cr:FileSet", f"croissant.json: unknown distribution type {e['@type']}")
            hits = [f for f in files if fnmatch.fnmatchcase(f, e["includes"])]
            expect(hits, f"croissant.json: FileSet {e['includes']} matches no file")
            expect(len(hits) == count, f"croissant.json: FileSet {e['includes']}: {len(hits)} files for {count} rows")
            sets[e["@id"]] = e["includes"]
            covered.update(hits)
    left = [f for f in files if f not in covered]
    expect(not left, f"croissant.json: files not described: {left[:5]}")
    described = {}  # file -> columns the fields read
    annotations = json.loads((d / "annotations.json").read_text()) if (d / "annotations.json").exists() else None
    for rs in c["recordSet"]:
        expect(rs["@type"] == "cr:RecordSet" and rs["field"], f"croissant.json: record set {rs.get('@id')} is empty")
        for f in rs["field"]:
            src, ext = f["source"], f["source"].get("extract", {})
            if "fileSet" in src:
                expect(src["fileSet"]["@id"] in sets, f"croissant.json: {f['@id']}: no FileSet {src['fileSet']}")
                expect(ext.get("fileProperty") in ("content", "filepath"), f"croissant.json: {f['@id']}: bad extract")
                continue
            fid = src["fileObject"]["@id"]
            expect(fid in objects, f"croissant.json: {f['@id']}: source {fid} is not in the distribution")
            name = objects[fid]
            described.setdefault(name, set())
            if "jsonPath" in ext:
                expect(name == "annotations.json", f"croissant.json: {f['@id']}: jsonPath into {name}")
                json_path_values(annotations, ext["jsonPath"])
                continue
            col = ext["column"]
            described[name].add(col)
            shape = tuple(int(x) for x in f["arrayShape"].split(",")) if f.get("isArray") else ()
            if name.endswith(".csv"):
                header = (d / name).read_text().split("\n", 1)[0].rstrip("\r").split(",")
                expect(col in header, f"croissant.json: {f['@id']}: {name} has no column {col}")
            elif name.endswith(".arff"):
                attrs = [ln.split()[1] for ln in (d / name).read_text().split("@data")[0].splitlines()
                         if ln.startswith("@attribute ")]
                expect(col in attrs, f"croissant.json: {f['@id']}: {name} has no attribute {col}")
            elif name == "data.h5":
                with h5py.File(d / name, "r") as h:
                    expect(col in h, f"croissant.json: {f['@id']}: data.h5 has no dataset {col}")
                    expect(h[col].shape == (count, *shape), f"croissant.json: {f['@id']}: shape {h[col].shape}")
            elif name == "features.npy":
                cols = (d / "features.columns.txt").read_text().split()
                expect(col in cols, f"croissant.json: {f['@id']}: features.npy has no column {col}")
            else:
                expect(name.endswith(".npy") and col == name[:-4], f"croissant.json: {f['@id']}: column {col} of {name}")
                a = np.load(d / name, mmap_mode="r")
                expect(a.shape == (count, *shape), f"croissant.json: {f['@id']}: {name} has shape {a.shape}")
    # Nothing left out: every column, dataset and tensor has its field.
    for name in described:
        if name.endswith(".csv"):
            have = set((d / name).read_text().split("\n", 1)[0].rstrip("\r").split(","))
        elif name == "data.h5":
            with h5py.File(d / name, "r") as h:
                have = set(h.keys())
        elif name == "features.npy":
            have = set((d / "features.columns.txt").read_text().split())
        else:
            continue
        expect(have == described[name], f"croissant.json: {name}: undescribed {sorted(have - described[name])[:5]}")
    for o in manifest["outputs"]:
        n = o["name"]
        if n.endswith((".csv", ".arff", ".h5", ".npy")):
            expect(n in described, f"croissant.json: {n} has no record set")
    return c


def front_matter(d):
    text = (d / "README.md").read_text()
    expect(text.startswith("---\n"), "README.md: no YAML front matter")
    return yaml.safe_load(text.split("---\n", 2)[1])


def check_card(d, manifest):
    fm = front_matter(d)
    for k in ("name", "version", "license", "command", "spec", "seed", "count", "counts", "class_balance",
              "sensor_model", "files"):
        expect(k in fm, f"README.md: front matter has no {k}")
    expect(fm["version"] == manifest["portalsim"], "README.md: version differs from the manifest")
    expect(fm["spec"] == manifest["spec"] and fm["seed"] == manifest["spec"]["seed"], "README.md: spec differs")
    expect(fm["count"] == manifest["count"], "README.md: count differs")
    expect(fm["counts"] == manifest["classes"], "README.md: counts differ from the manifest's classes")
    expect(abs(fm["class_balance"] - manifest["classes"]["positive"] / manifest["count"]) < 1e-6,
           "README.md: class_balance is not the share of positives")
    expect(fm["sensor_model"]["name"] == manifest["spec"]["model"], "README.md: sensor model differs")
    for k, v in fm["sensor_model"]["parameters"].items():
        expect(manifest["spec"][k] == v, f"README.md: sensor parameter {k} differs from the spec")
    named = {f["name"] for f in fm["files"]}
    for o in manifest["outputs"]:
        expect(o["name"] in named, f"README.md: files does not list {o['name']}")
    for n in named:
        expect((d / n).exists(), f"README.md: files lists {n}, which does not exist")
    expect(fm["command"].startswith("portalsim generate ") and fm["command"].endswith(" --out DIR"),
           f"README.md: command {fm['command']!r}")
    return fm


def card_bytes(d):
    return tuple((d / n).read_bytes() for n in CARD_FILES)


def check_folder(d):
    manifest = json.loads((d / "manifest.json").read_text())
    check_croissant(d, manifest)
    return check_card(d, manifest)


def remake(portalsim, d, fm, work):
    """The card's command, run: the same outputs, byte for byte, and the same card."""
    argv = shlex.split(fm["command"])
    again = work / (d.name + "-again")
    argv = [portalsim] + argv[1:-1] + [str(again), "--quiet"]
    subprocess.run(argv, check=True, stdout=subprocess.DEVNULL)
    a = json.loads((d / "manifest.json").read_text())
    b = json.loads((again / "manifest.json").read_text())
    expect(a == b, f"{fm['command']}: its manifest differs from the card's data set's")
    expect(card_bytes(d) == card_bytes(again), f"{fm['command']}: its card differs")


def check_checker(d, work):
    """The checks can fail: a described file that does not exist, and a dataset left out."""
    bad = work / "checker"
    shutil.copytree(d, bad)
    manifest = json.loads((bad / "manifest.json").read_text())
    good = json.loads((d / "croissant.json").read_text())

    def add_missing_file(c):
        c["distribution"].append({**c["distribution"][0], "@id": "nothing.csv", "contentUrl": "nothing.csv"})

    def drop_h5_field(c):
        h5 = next(rs for rs in c["recordSet"] if rs["@id"] == "data_h5")
        h5["field"] = h5["field"][1:]

    for broken, mutate in (("a file that does not exist", add_missing_file),
                           ("a data.h5 dataset without a field", drop_h5_field)):
        c = json.loads(json.dumps(good))
        mutate(c)
        (bad / "croissant.json").write_text(json.dumps(c))
        try:
            check_croissant(bad, manifest)
        except AssertionError:
            continue
        raise AssertionError(f"the check passed a croissant.json with {broken}")


def main():
    portalsim, work = sys.argv[1], pathlib.Path(sys.argv[2])
    shutil.rmtree(work, ignore_errors=True)
    work.mkdir(parents=True)
    cases = {
        "tables": ["--count", "40", "--seed", "3", "--rule", "gun", "--what", "both", "--format", "arff,csv,npy"],
        "h5": ["--count", "40", "--seed", "4", "--rule", "gun", "--balance", "--what", "images", "--format", "h5",
               "--annotations", "--rotate", "20"],
        "npy": ["--count", "30", "--seed", "5", "--rule", "iron-rod&metal-plate", "--what", "images", "--format", "npy",
                "--annotations"],
        "physics": ["--count", "50", "--seed", "6", "--rule", "gun", "--what", "features", "--format", "h5,csv",
                    "--model", "physics", "--pattern-noise", "off", "--netd", "2.5", "--metal-noise", "0..6"],
    }
    cards = {}
    for name, args in cases.items():
        d = work / name
        generate(portalsim, d, args)
        cards[name] = check_folder(d)
        print(f"{name}: croissant.json and README.md describe every file and field")
    for name in ("h5", "physics"):
        remake(portalsim, work / name, cards[name], work)
        print(f"{name}: the card's command makes the same data set")
    check_checker(work / "h5", work)

    # Byte identity: another batch and thread count; shards joined by merge.
    for name in ("tables", "physics"):
        d = work / name
        other = work / (name + "-batch")
        generate(portalsim, other, cases[name] + ["--batch", "7", "--threads", "1"])
        expect(card_bytes(other) == card_bytes(d), f"{name}: the card differs for --batch 7 --threads 1")
        parts = []
        for i, k in (("0", "2"), ("1", "2")):
            p = work / f"{name}-part{i}"
            generate(portalsim, p, cases[name] + ["--shard", f"{i}/{k}"])
            check_folder(p)
            parts.append(str(p))
        whole = work / (name + "-merged")
        subprocess.run([portalsim, "merge", *parts, "--out", str(whole)], check=True, stdout=subprocess.DEVNULL)
        expect(card_bytes(whole) == card_bytes(d), f"{name}: the merged card differs from the whole run's")
        print(f"{name}: the same card for --batch/--threads and for shards joined by merge")
    print("dataset card and Croissant: ok")


if __name__ == "__main__":
    try:
        main()
    except AssertionError as e:
        print(f"FAILED: {e}", file=sys.stderr)
        sys.exit(1)
