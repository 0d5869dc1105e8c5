"""The plots of `portalsim validate` (embedded in the binary): DIR/report.json to
DIR/accuracy.png (cross-validated accuracy per classifier and data set, with the spread of
the fold accuracies over all runs; one panel per feature set) and DIR/curve.png (the
learning curve, one panel per feature set)."""
import json
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

folder = sys.argv[1]
report = json.load(open(folder + "/report.json"))
# The thesis's order: region means (tables 6.1/6.3/6.5) before block means (6.2/6.4/6.6).
analyses = [(k, report["analyses"][k]) for k in ("regions", "blocks", "all") if k in report["analyses"]]
sets = ["real", "sim", "combined"]

fig, axes = plt.subplots(1, len(analyses), figsize=(7 * len(analyses), 4), squeeze=False)
for ax, (key, a) in zip(axes[0], analyses):
    names = list(a["classifiers"])
    width = 0.25
    for k, s in enumerate(sets):
        means, lows, highs = [], [], []
        for c in names:
            folds = [f for run in a["classifiers"][c][s]["runs"] for f in run["folds"]]
            m = a["classifiers"][c][s]["mean_percent_correct"]
            means.append(m)
            lows.append(m - min(folds))
            highs.append(max(folds) - m)
        xs = [i + (k - 1) * width for i in range(len(names))]
        ax.bar(xs, means, width, yerr=[lows, highs], capsize=3, label=s)
    ax.set_xticks(range(len(names)))
    ax.set_xticklabels(names)
    ax.set_ylabel("% correct (bars: fold min to max)")
    ax.set_ylim(0, 105)
    ax.legend(loc="lower right")
    ax.set_title("Cross-validated accuracy, %s (%d attributes)" % (a["feature_set"], a["attributes"]))
fig.tight_layout()
fig.savefig(folder + "/accuracy.png", dpi=100)

fig, axes = plt.subplots(1, len(analyses), figsize=(7 * len(analyses), 4), squeeze=False)
for ax, (key, a) in zip(axes[0], analyses):
    for c in a["classifiers"]:
        curve = a["classifiers"][c].get("learning_curve")
        if curve:
            ax.plot([p["sim_added"] for p in curve], [p["percent_correct"] for p in curve], marker="o", label=c)
    if ax.lines:
        ax.legend()
    else:
        ax.text(0.5, 0.5, "no learning curve (--curve-steps 0)", ha="center", transform=ax.transAxes)
    ax.set_xlabel("simulated scenarios added to the real training folds")
    ax.set_ylabel("% correct on held-out real data")
    ax.set_title("Learning curve, %s" % a["feature_set"])
fig.tight_layout()
fig.savefig(folder + "/curve.png", dpi=100)
