#!/usr/bin/env python3
"""The real-camera table: thesis case 2 (an iron rod AND a metal plate) classified with the
thesis's protocol, for the real camera (the thesis's Tables 6.1 and 6.2), the thesis model
and the physics model, each with its sampling interval.

    /usr/bin/python3 tools/real_camera_table.py build/portalsim [--count 1000] [--out DIR]
        [--classifiers j48,mlp,svm] [--physics KNOB=VALUE ...] [--models thesis,physics]
        [--skip FEATURES/CLASSIFIER,...] [--mlp-options "-H 20 -N 100"]

For each model it runs `portalsim generate --spec scenarios/case2-rod-plate.toml` (block
10: the thesis's 10 x 10 pixel groups), splits the feature table into the thesis's two
feature sets (region means and the metal zones; 10 x 10 block means of both MMW views and
the metal zones), and scores WEKA's J48, MultilayerPerceptron and SMO (default settings)
by 10-fold cross-validation (`java -cp /usr/share/java/weka.jar CLASSIFIER -t FILE -x 10
-s 1 -o`). MultilayerPerceptron takes --mlp-options (default one hidden layer of 20 units
and 100 epochs: WEKA's default, a layer of (attributes + classes) / 2 units and 500 epochs,
is 410 units on the block means and takes hours on two cores). Each accuracy p over n profiles has the interval p +- 1.96 sqrt(p (1 - p) / n).
Prints a Markdown table and writes it (and every WEKA log) under --out.
"""
import argparse
import math
import re
import subprocess
import sys
import tempfile
from pathlib import Path

REAL = {  # thesis Tables 6.1 (region means) and 6.2 (10 x 10 pixel groups), 124 profiles
    ("regions", "j48"): 91.94, ("regions", "mlp"): 97.11, ("regions", "svm"): 95.19,
    ("blocks", "j48"): 90.33, ("blocks", "mlp"): 95.96, ("blocks", "svm"): 92.74,
}
REAL_PROFILES = 124
WEKA = {"j48": "weka.classifiers.trees.J48", "mlp": "weka.classifiers.functions.MultilayerPerceptron",
        "svm": "weka.classifiers.functions.SMO"}
NAMES = {"j48": "J48", "mlp": "MLP", "svm": "SVM"}
ROOT = Path(__file__).resolve().parent.parent


def interval(p, n):
    """The normal-approximation 95% half-width of an accuracy p (percent) over n cases."""
    q = p / 100
    return 196 * math.sqrt(q * (1 - q) / n)


def generate(portalsim, out, model, count, seed, knobs):
    cmd = [portalsim, "generate", "--spec", str(ROOT / "scenarios/case2-rod-plate.toml"), "--count", str(count),
           "--seed", str(seed), "--model", model, "--block", "10", "--format", "arff", "--out", str(out)]
    for k in knobs:
        key, _, value = k.partition("=")
        cmd += ["--" + key.replace("_", "-"), value]
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
    return out / "features.arff"


def split(arff, folder):
    """The thesis's two feature sets as ARFF files: region means + zones, blocks + zones."""
    lines = arff.read_text().splitlines()
    head = [i for i, l in enumerate(lines) if l.lower().startswith("@attribute")]
    data = next(i for i, l in enumerate(lines) if l.lower().startswith("@data"))
    names = [lines[i].split()[1] for i in head]
    keep = {
        "regions": [i for i, n in enumerate(names) if n.startswith("region") or n.startswith("zone")],
        "blocks": [i for i, n in enumerate(names) if re.fullmatch(r"\w+_r\d+_c\d+", n) or n.startswith("zone")],
    }
    label = len(names) - 1
    out = {}
    for name, cols in keep.items():
        cols = cols + [label]
        text = lines[:head[0]] + [lines[head[c]] for c in cols] + ["@data"]
        for row in lines[data + 1:]:
            if row.strip():
                v = row.split(",")
                text.append(",".join(v[c] for c in cols))
        path = folder / f"{name}.arff"
        path.write_text("\n".join(text) + "\n")
        out[name] = (path, len(cols) - 1)
    return out


def weka(classifier, arff, log, options=()):
    r = subprocess.run(["java", "-Xmx4g", "-cp", "/usr/share/java/weka.jar", WEKA[classifier], "-t", str(arff),
                        "-x", "10", "-s", "1", "-o", *options], check=True, capture_output=True, text=True)
    log.write_text(r.stdout)
    # The cross-validation section comes last: its "Correctly Classified Instances" line.
    hits = re.findall(r"Correctly Classified Instances\s+\d+\s+([\d.]+)\s*%", r.stdout)
    return float(hits[-1])


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("portalsim")
    ap.add_argument("--count", type=int, default=1000)
    ap.add_argument("--seed", type=int, default=25)
    ap.add_argument("--out", default=None)
    ap.add_argument("--classifiers", default="j48,mlp,svm")
    ap.add_argument("--models", default="thesis,physics")
    ap.add_argument("--physics", nargs="*", default=[], metavar="KNOB=VALUE")
    ap.add_argument("--skip", default="none", help="FEATURES/CLASSIFIER pairs left out, e.g. blocks/mlp")
    ap.add_argument("--mlp-options", default="-H 20 -N 100",
                    help="MultilayerPerceptron's options (default: 20 hidden units, 100 epochs)")
    a = ap.parse_args()
    out = Path(a.out or tempfile.mkdtemp(prefix="real_camera_"))
    out.mkdir(parents=True, exist_ok=True)
    classifiers = a.classifiers.split(",")
    models = a.models.split(",")
    results = {}
    for model in models:
        folder = out / model
        folder.mkdir(exist_ok=True)
        arff = generate(a.portalsim, folder / "data", model, a.count, a.seed, a.physics if model == "physics" else [])
        for fs, (path, attrs) in split(arff, folder).items():
            for c in classifiers:
                if f"{fs}/{c}" in a.skip.split(","):
                    continue
                options = a.mlp_options.split() if c == "mlp" else ()
                results[(model, fs, c)] = weka(c, path, folder / f"{fs}.{c}.txt", options)
                print(f"{model} {fs} ({attrs} attributes) {NAMES[c]}: {results[(model, fs, c)]:.2f}%",
                      file=sys.stderr, flush=True)
    knobs = " ".join("--" + k.replace("_", "-").replace("=", " ") for k in a.physics)
    rows = ["| feature set | classifier | real camera (124 profiles) | " +
            " | ".join(f"{m} model ({a.count} scenarios)" for m in models) + " |",
            "| --- | --- | --- | " + " | ".join("---" for _ in models) + " |"]
    for fs, fs_name in [("regions", "region means + zones (Table 6.1)"), ("blocks", "10x10 block means + zones (Table 6.2)")]:
        for c in classifiers:
            real = REAL[(fs, c)]
            cells = []
            for m in models:
                if (m, fs, c) not in results:
                    cells.append("not run (--skip)")
                    continue
                p = results[(m, fs, c)]
                inside = abs(p - real) <= interval(real, REAL_PROFILES)
                cells.append(f"{p:.2f} +- {interval(p, a.count):.1f}" + ("" if inside else " (outside)"))
            rows.append(f"| {fs_name} | {NAMES[c]} | {real:.2f} +- {interval(real, REAL_PROFILES):.1f} | " +
                        " | ".join(cells) + " |")
    table = "\n".join(rows)
    note = (f"thesis case 2, {a.count} scenarios per model (seed {a.seed}), WEKA 10-fold CV (-s 1), MLP "
            f"{a.mlp_options}; physics knobs: "
            f"{knobs or 'the defaults'}; (outside): farther from the real camera's figure than its interval")
    print(table + "\n\n" + note)
    (out / "table.md").write_text(table + "\n\n" + note + "\n")


if __name__ == "__main__":
    main()
