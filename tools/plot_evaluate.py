#!/usr/bin/env python3
"""The plots of `portalsim evaluate` (embedded in the binary), from DIR/report.json and
DIR/roc.csv: DIR/roc.png (the ROC of each sensor and fusion, whole and at low Pfa, with Pd
at each target Pfa marked) and, where the data set has per-region labels, DIR/regions.png
(Pd at the middle target Pfa of "a threat is in this region", drawn on the body: subject
1's MMW views, DIR/.body_<view>.png, which evaluate writes for this and removes).
Usage: plot_evaluate.py DIR"""
import csv
import json
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib import cm, colors, patches  # noqa: E402

folder = sys.argv[1]
report = json.load(open(os.path.join(folder, "report.json")))
curves = {}
with open(os.path.join(folder, "roc.csv")) as f:
    for row in csv.DictReader(f):
        c = curves.setdefault(row["entry"], ([], []))
        c[0].append(float(row["pfa"]))
        c[1].append(float(row["pd"]))

order = report["entry_order"]
targets = [p["pfa_target"] for p in report["entries"][order[0]]["pd_at_pfa"]]
fig, axes = plt.subplots(1, 2, figsize=(13, 5.5))
palette = plt.get_cmap("tab10")
for i, name in enumerate(order):
    e = report["entries"][name]
    style = "-" if not name.startswith("fused_") else "--"
    label = "%s (AUC %.3f)" % (name, e["auc"])
    for ax in axes:
        ax.plot(*curves[name], style, color=palette(i % 10), lw=1.6, label=label, drawstyle="steps-post")
    for p in e["pd_at_pfa"]:
        axes[1].plot([p["pfa"]], [p["pd"]], "o", color=palette(i % 10), ms=4)
axes[0].plot([0, 1], [0, 1], ":", color="grey", lw=1)
axes[0].set_title("ROC, out-of-fold scores")
axes[1].set_xlim(0, min(1.0, 2 * max(targets)))
axes[1].set_title("Low false-alarm rates (dots: Pd at Pfa %s)" % ", ".join("%g%%" % (100 * t) for t in targets))
for t in targets:
    axes[1].axvline(t, color="grey", lw=0.8, ls=":")
for ax in axes:
    ax.set_xlabel("Pfa (share of non-threats that alarm)")
    ax.set_ylabel("Pd (share of threats that alarm)")
    ax.set_ylim(0, 1.01)
    ax.grid(alpha=0.3)
axes[1].legend(loc="lower right", fontsize=8)
fig.suptitle("%s: %d scenarios, %d threats; solid: one sensor, dashed: fused" %
             (report["data"]["source"], report["rows"], report["positives"]))
fig.tight_layout()
fig.savefig(os.path.join(folder, "roc.png"), dpi=110)

if report["regions"]:
    k = min(1, len(targets) - 1)
    places = {p["name"]: p for p in report["data"]["region_places"]}
    views = sorted({p["view"] for p in places.values() if p["view"]}, key=lambda v: (v != "upper", v))
    fig, axes = plt.subplots(1, len(views) + 1, figsize=(4.2 * len(views) + 0.6, 5),
                             gridspec_kw={"width_ratios": [1] * len(views) + [0.06]})
    norm = colors.Normalize(0, 1)
    cmap = plt.get_cmap("RdYlGn")
    for ax, view in zip(axes, views):
        body = os.path.join(folder, ".body_%s.png" % view)
        if os.path.exists(body):
            ax.imshow(plt.imread(body), cmap="gray", vmin=0, vmax=1)
        ax.set_title("%s view" % view)
        ax.set_xticks([])
        ax.set_yticks([])
        for g in report["regions"]:
            p = places[g["name"]]
            if p["view"] != view:
                continue
            x, y, w, h = p["rect"]
            if "pd_at_pfa" in g:
                pd = g["pd_at_pfa"][k]["pd"]
                ax.add_patch(patches.Rectangle((x, y), w, h, facecolor=cmap(norm(pd)), alpha=0.75, edgecolor="black"))
                text = "%s\nPd %.0f%%\nAUC %.2f" % (p["region"].replace("-", "\n"), 100 * pd, g["auc"])
            else:
                ax.add_patch(patches.Rectangle((x, y), w, h, fill=False, edgecolor="black", hatch="//"))
                text = "%s\nno threats" % p["region"].replace("-", "\n")
            ax.text(x + w / 2, y + h / 2, text, ha="center", va="center", fontsize=6.5)
    fig.colorbar(cm.ScalarMappable(norm=norm, cmap=cmap), cax=axes[-1], label="Pd at Pfa %g%%" % (100 * targets[k]))
    fig.suptitle("A threat in this region: Pd at Pfa %g%% per region (mean log loss %.3f, baseline %.3f)" %
                 (100 * targets[k], report["log_loss"]["mean_over_regions"],
                  report["log_loss"]["baseline_mean_over_regions"]))
    fig.tight_layout()
    fig.savefig(os.path.join(folder, "regions.png"), dpi=110)
