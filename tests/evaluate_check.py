#!/usr/bin/env python3
"""ctest evaluate.python: `portalsim evaluate` as a user runs it.

- Its numbers against an independent computation on the very scores it writes
  (scores.csv): AUC and the ROC's points against scikit-learn's roc_auc_score and
  roc_curve(drop_intermediate=False), Pd at each target Pfa from scikit-learn's curve, each
  region's log loss against scikit-learn's log_loss and the direct formula, the stacking's
  AUC against scikit-learn's logistic regression on the same out-of-fold logits.
- The same scores from the data set's CSV, ARFF and data.h5, and from a CSV the fast reader
  leaves to the general one; the same bytes run to run and
  for any --threads; --spec generates first.
- A sweep: resumed after a point is lost, and split in two --part runs, it gives the same
  bytes as one whole run.
- Bad input, each refused with its exit code and a message naming the field or flag, and no
  report left: an unknown knob in a sweep, an empty and a reversed range, a Pfa outside
  0..1, a data set without labels, a folder that is none, a read-only output folder (a
  read-only tmpfs, in a private mount namespace: CI runs as root).

Usage: evaluate_check.py PORTALSIM WORK_DIR   (Debian's python3: python3-sklearn)"""
import csv
import filecmp
import json
import math
import os
import shutil
import subprocess
import sys

from sklearn.linear_model import LogisticRegression
from sklearn.metrics import log_loss, roc_auc_score, roc_curve
from sklearn.model_selection import PredefinedSplit, cross_val_predict

portalsim, work = os.path.abspath(sys.argv[1]), os.path.abspath(sys.argv[2])
shutil.rmtree(work, ignore_errors=True)
os.makedirs(work)
os.chdir(work)
spec = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "scenarios", "case2-rod-plate.toml")
failures = []


def check(ok, what):
    if not ok:
        failures.append(what)
        print("FAIL:", what, flush=True)


def run(args, expect=0):
    r = subprocess.run([portalsim] + args, capture_output=True, text=True)
    if r.returncode != expect:
        print(r.stdout[-3000:], r.stderr[-3000:])
        raise SystemExit("portalsim %s: exit %d, expected %d" % (" ".join(args), r.returncode, expect))
    return r


def same_tree(a, b):
    """Whether two folders hold the same files with the same bytes."""
    cmp = filecmp.dircmp(a, b)
    if cmp.left_only or cmp.right_only or cmp.funny_files:
        return False
    _, mismatch, errors = filecmp.cmpfiles(a, b, cmp.common_files, shallow=False)
    return not mismatch and not errors and all(same_tree(os.path.join(a, d), os.path.join(b, d)) for d in cmp.common_dirs)


# The data: thesis case 2, 600 scenarios, every table format generate writes features to.
run(["generate", "--spec", spec, "--count", "600", "--format", "csv,arff,h5", "--out", "data", "--quiet"])
os.makedirs("data-arff")
os.makedirs("data-h5")
for name in ("manifest.json", "scenarios.csv"):
    shutil.copy(os.path.join("data", name), "data-arff")
    shutil.copy(os.path.join("data", name), "data-h5")
shutil.copy("data/features.arff", "data-arff")
shutil.copy("data/data.h5", "data-h5")

run(["evaluate", "data", "--out", "r1", "--threads", "1"])
report = json.load(open("r1/report.json"))
with open("r1/scores.csv") as f:
    rows = list(csv.DictReader(f))
labels = [int(r["label"]) for r in rows]
targets = [p["pfa_target"] for p in report["entries"]["metal"]["pd_at_pfa"]]
check(report["entry_order"] == ["upper", "lower", "metal", "fused_features", "fused_or", "fused_and",
                                "fused_majority", "fused_stacking"], "entries: %s" % report["entry_order"])
curves = {}
with open("r1/roc.csv") as f:
    for r in csv.DictReader(f):
        curves.setdefault(r["entry"], []).append(r)

# Each entry: AUC, the ROC's points and Pd at each target against scikit-learn.
for name in report["entry_order"]:
    e = report["entries"][name]
    scores = [float(r[name]) for r in rows]
    auc = roc_auc_score(labels, scores)
    check(abs(auc - e["auc"]) < 1e-12, "%s: AUC %r, scikit-learn %r" % (name, e["auc"], auc))
    check(e["auc_interval"][0] <= e["auc"] <= e["auc_interval"][1], "%s: AUC outside its interval" % name)
    fpr, tpr, _ = roc_curve(labels, scores, drop_intermediate=False)
    mine = curves[name]
    check(len(mine) == len(fpr), "%s: %d ROC points, scikit-learn %d" % (name, len(mine), len(fpr)))
    check(all(abs(float(m["pfa"]) - x) < 1e-12 and abs(float(m["pd"]) - y) < 1e-12
              for m, x, y in zip(mine, fpr, tpr)), "%s: ROC points differ from scikit-learn's" % name)
    for p, t in zip(e["pd_at_pfa"], targets):
        best = max(y for x, y in zip(fpr, tpr) if x <= t + 1e-12)
        check(abs(p["pd"] - best) < 1e-12, "%s: Pd at Pfa %g is %r, from scikit-learn's curve %r" %
              (name, t, p["pd"], best))
        check(p["pfa"] <= t and p["pd_interval"][0] <= p["pd"] <= p["pd_interval"][1],
              "%s: Pd at Pfa %g: achieved Pfa or interval wrong" % (name, t))

# Stacking: a logistic regression on the sensors' out-of-fold logits, on the same folds, as
# scikit-learn's (nearly unregularised) gives it: the AUCs agree to 0.0005 (measured: 3e-5).
sensors = report["sensors"]
fold = [int(r["fold"]) for r in rows]
X = [[math.log(min(max(float(r[s]), 1e-6), 1 - 1e-6) / (1 - min(max(float(r[s]), 1e-6), 1 - 1e-6))) for s in sensors]
     for r in rows]
stacked = cross_val_predict(LogisticRegression(C=1e4, max_iter=2000), X, labels, cv=PredefinedSplit(fold),
                            method="predict_proba")[:, 1]
ref = roc_auc_score(labels, stacked)
check(abs(report["entries"]["fused_stacking"]["auc"] - ref) < 0.0005,
      "fused_stacking: AUC %r, scikit-learn's logistic regression on the same logits %r" %
      (report["entries"]["fused_stacking"]["auc"], ref))

# Each region: log loss against scikit-learn and the direct formula; the mean over regions.
losses = []
for g in report["regions"]:
    y = [int(r[g["name"] + "_label"]) for r in rows]
    p = [float(r[g["name"] + "_probability"]) for r in rows]
    ref = log_loss(y, p, labels=[0, 1])
    direct = -sum(math.log(min(max(q, 1e-15), 1 - 1e-15)) if t else math.log(1 - min(max(q, 1e-15), 1 - 1e-15))
                  for t, q in zip(y, p)) / len(y)
    check(abs(g["log_loss"] - ref) < 1e-9 and abs(g["log_loss"] - direct) < 1e-9,
          "%s: log loss %r, scikit-learn %r, direct %r" % (g["name"], g["log_loss"], ref, direct))
    check(g["threats"] == sum(y), "%s: threats %d, labels %d" % (g["name"], g["threats"], sum(y)))
    if "auc" in g:
        check(abs(g["auc"] - roc_auc_score(y, p)) < 1e-12, "%s: AUC against scikit-learn" % g["name"])
    losses.append(g["log_loss"])
check(abs(report["log_loss"]["mean_over_regions"] - sum(losses) / len(losses)) < 1e-12, "mean log loss")
check(sum(g["threats"] for g in report["regions"]) > 0, "no region holds a threat")
for f in ("report.md", "report.json", "scores.csv", "roc.csv", "roc.png", "regions.png"):
    check(os.path.exists(os.path.join("r1", f)), "r1/%s missing" % f)

# The same bytes run to run and for another thread count; the same scores from ARFF and data.h5.
run(["evaluate", "data", "--out", "r2", "--threads", "2"])
check(same_tree("r1", "r2"), "two runs (--threads 1 and 2) differ")
# A CSV that is not as generate writes it (blanks after the commas, a number with a plus
# sign) goes through the general reader, to the same numbers as the fast one.
os.makedirs("data-blanks")
for name in ("manifest.json", "scenarios.csv"):
    shutil.copy(os.path.join("data", name), "data-blanks")
with open("data/features.csv") as f, open("data-blanks/features.csv", "w") as g:
    for i, line in enumerate(f):
        fields = line.rstrip("\n").split(",")
        if i == 1 and not fields[0].startswith("-"):
            fields[0] = "+" + fields[0]
        g.write(", ".join(fields) + "\n")
for other in ("data-arff", "data-h5", "data-blanks"):
    run(["evaluate", other, "--out", "r-" + other, "--no-plot"])
    check(filecmp.cmp("r1/scores.csv", "r-%s/scores.csv" % other, shallow=False),
          "%s: scores differ from the CSV's" % other)

# --spec generates first, into the report's data/.
run(["evaluate", "--spec", spec, "--count", "200", "--out", "r-spec", "--no-plot", "--bootstrap", "100"])
check(os.path.exists("r-spec/data/features.csv") and os.path.exists("r-spec/report.json"), "--spec: files missing")

# A sweep: whole, resumed after a lost point, and in two parts, to the same bytes.
sweep = ["evaluate", "--spec", spec, "--count", "150", "--bootstrap", "50", "--sweep", "metal_noise=0,20 block=10,20"]
run(sweep + ["--out", "s1"])
check(sorted(os.listdir("s1/points")) == ["point-%04d" % i for i in range(4)], "sweep: points %s" %
      os.listdir("s1/points"))
shutil.copytree("s1", "s2")
shutil.rmtree("s2/points/point-0002")
for f in ("sweep.csv", "sweep.md", "sweep.png"):
    os.remove("s2/" + f)
run(sweep + ["--out", "s2"])
check(same_tree("s1", "s2"), "a resumed sweep differs from a whole one")
run(sweep + ["--out", "s3", "--part", "1/2"])
check(not os.path.exists("s3/sweep.csv") and sorted(os.listdir("s3/points")) == ["point-0001", "point-0003"],
      "--part 1/2 ran other points or wrote the table")
run(sweep + ["--out", "s3", "--part", "0/2"])
run(sweep + ["--out", "s3"])
check(same_tree("s1", "s3"), "a sweep in two parts differs from a whole one")
rows = list(csv.DictReader(open("s1/sweep.csv")))
check(len(rows) == 4 * 8 and rows[0]["metal_noise"] == "0" and rows[0]["block"] == "10", "sweep.csv rows")
run(["evaluate", "--spec", spec, "--count", "150", "--bootstrap", "50", "--no-plot", "--samples", "3",
     "--sweep", "pixel_noise=0..6", "--out", "s4"])
drawn = [float(p["pixel_noise"]) for p in json.load(open("s4/sweep.json"))["points"]]
check(sorted(int(v / 2) for v in drawn) == [0, 1, 2], "Latin hypercube: one draw per third of the range: %s" % drawn)

# Bad input: the exit code, the field or flag named, and no report.
shutil.copytree("data", "nolabels")
with open("data/features.csv") as f:
    lines = f.read().splitlines()
with open("nolabels/features.csv", "w") as f:
    f.write("\n".join([lines[0]] + [line.rsplit(",", 1)[0] + ",negative" for line in lines[1:]]) + "\n")
for name, value in (("unlabelled", "?"), ("badclass", "maybe")):
    shutil.copytree("data", name)
    with open(name + "/features.csv", "w") as f:
        f.write("\n".join([lines[0]] + [line.rsplit(",", 1)[0] + "," + value for line in lines[1:]]) + "\n")
shutil.copytree("data", "nomanifest")
os.remove("nomanifest/manifest.json")
bad = [
    (["--sweep", "nosuch=1,2", "--spec", spec], 2, "nosuch"),
    (["--samples", "3", "--sweep", "netd=2..2", "--spec", spec, "--model", "physics"], 2, "empty"),
    (["--samples", "3", "--sweep", "netd=3..1", "--spec", spec, "--model", "physics"], 2, "reversed"),
    (["--sweep", "netd=1,abc", "--spec", spec], 2, "--sweep netd"),
    (["data", "--pfa", "0.05,1.5"], 2, "--pfa"),
    (["data", "--pfa", "0"], 2, "--pfa"),
    (["data", "--folds", "1"], 2, "--folds"),
    (["nolabels"], 3, "field 'class'"),
    (["unlabelled"], 3, "field 'class' is missing"),
    (["badclass"], 3, "field 'class' is \"maybe\""),
    (["nomanifest"], 3, "manifest.json"),
    (["no-such-folder"], 3, "no-such-folder"),
    (["data/features.csv"], 3, "not a folder"),
    ([], 2, "nothing to evaluate"),
    (["data", "--spec", spec], 2, "more than one"),
    (["data", "--netd", "2"], 2, "--netd"),
]
for i, (args, code, text) in enumerate(bad):
    out = "bad%d" % i
    r = run(["evaluate"] + args + ["--out", out], expect=code)
    check(text in r.stderr, "%s: message %r lacks %r" % (args, r.stderr.strip(), text))
    check(not os.path.exists(out), "%s: left %s behind" % (args, out))
# A scenarios.csv that does not match the table: found after the report's folder exists.
shutil.copytree("data", "short")
with open("short/scenarios.csv") as f:
    head = f.read().splitlines()[:50]
with open("short/scenarios.csv", "w") as f:
    f.write("\n".join(head) + "\n")
r = run(["evaluate", "short", "--out", "bad-short"], expect=3)
check("scenarios.csv" in r.stderr and not os.path.exists("bad-short"), "short scenarios.csv: %s" % r.stderr)
# A read-only output folder: nothing written, exit 4.
mnt = os.path.join(work, "mnt")
os.makedirs(mnt)
script = ("mount -t tmpfs -o size=1m tmpfs %s && mkdir %s/out && mount -o remount,ro %s && %s evaluate %s --out "
          "%s/out/report; rc=$?; find %s -mindepth 1 > %s/listing; exit $rc" %
          (mnt, mnt, mnt, portalsim, os.path.join(work, "data"), mnt, mnt, work))
r = subprocess.run(["unshare", "-m", "sh", "-c", script], capture_output=True, text=True)
check(r.returncode == 4, "read-only --out: exit %d, %s" % (r.returncode, r.stderr))
check(open(os.path.join(work, "listing")).read().split() == [mnt + "/out"], "read-only --out: left %s" %
      open(os.path.join(work, "listing")).read())

if failures:
    raise SystemExit("%d failures" % len(failures))
print("evaluate.python: every check passed")
