#!/usr/bin/env python3
"""Draws tradeoff.png from tradeoff.json: throughput against error per fidelity tier, one
row of panels per sensor model, with the Pareto front (no other tier of that model is both
faster and more accurate) marked.
Usage: plot_tradeoff.py DIR   (reads DIR/tradeoff.json, writes DIR/tradeoff.png)"""
import json
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def pareto(points):
    """Indices of points not dominated: higher throughput and lower error is better."""
    front = []
    for i, (x, y) in enumerate(points):
        if not any((x2 >= x and y2 <= y) and (x2 > x or y2 < y) for j, (x2, y2) in enumerate(points) if j != i):
            front.append(i)
    return sorted(front, key=lambda i: points[i][0])


def accuracy_panel(ax, rows, model):
    """J48's 10-fold accuracy per tier on thesis cases 1 and 2, as grouped bars."""
    width = 0.38
    for k, (key, case) in enumerate((("j48_accuracy", "case 1 (gun)"), ("j48_case2_accuracy", "case 2 (rod & plate)"))):
        xs = [i + (k - 0.5) * width for i in range(len(rows))]
        accs = [r.get(key) for r in rows]
        bars = ax.bar([x for x, a in zip(xs, accs) if a is not None], [a for a in accs if a is not None], width,
                      color="C%d" % (k + 1), label=case)
        ax.bar_label(bars, fmt="%.1f", fontsize=7)
    ax.set_xticks(range(len(rows)), [r["name"] for r in rows], fontsize=8)
    ax.set_ylim(0, 110)
    ax.set_ylabel("J48 10-fold accuracy (%)")
    ax.set_title("%s model: classifier per tier" % model, fontsize=10)
    ax.legend(fontsize=8, loc="lower right")


def main():
    out = sys.argv[1]
    data = json.load(open(os.path.join(out, "tradeoff.json")))
    models = data["models"]
    classifier = any(r.get("j48_accuracy") is not None for r in data["rows"])
    # One row of panels per sensor model; each tier's error is against that model's own
    # fp64 reference, and the columns share their throughput axis across models.
    cols = 3 if classifier else 2
    fig, axes = plt.subplots(len(models), cols, figsize=(5.6 * cols, 4.6 * len(models)), squeeze=False)
    panels = [("features_per_s", "feature_max_abs", "features-only throughput (scenarios/s)",
               "max |feature error| vs own fp64 reference"),
              ("images_per_s", "mmw_rmse_mean", "all-sensor image throughput (scenarios/s)",
               "mean per-image MMW RMSE vs own reference")]
    for row_axes, model in zip(axes, models):
        rows = [r for r in data["rows"] if r["model"] == model]
        for ax, (xk, yk, xl, yl) in zip(row_axes, panels):
            pts = [(r[xk], max(r[yk], 1e-7)) for r in rows]
            front = pareto(pts)
            for i, r in enumerate(rows):
                ax.scatter(pts[i][0], pts[i][1], s=70, marker="*" if i in front else "o",
                           color="C3" if i in front else "C0", zorder=3)
                # Alternate label sides so that tiers landing close together stay readable.
                ax.annotate(r["name"], pts[i], textcoords="offset points", xytext=(6, 6 if i % 2 else -12),
                            fontsize=8)
            ax.plot([pts[i][0] for i in front], [pts[i][1] for i in front], "--", color="C3", label="Pareto front")
            xs = [r[xk] for r in data["rows"]]
            if max(xs) > 10 * min(xs):  # a log axis only where the range calls for one
                ax.set_xscale("log")
            ax.set_xlim(min(xs) / 1.5, max(xs) * 1.5)
            ax.set_yscale("log")
            ax.set_xlabel(xl)
            ax.set_ylabel(yl)
            ax.set_title("%s model" % model, fontsize=10)
            ax.grid(True, which="both", alpha=0.3)
            ax.legend(fontsize=8)
        if classifier:
            accuracy_panel(row_axes[2], rows, model)
    fig.suptitle("portalsim fidelity tiers per sensor model: %d scenarios, %s" % (data["count"], data["machine"]),
                 fontsize=10)
    fig.tight_layout()
    tmp = os.path.join(out, "tradeoff.png.tmp.png")
    fig.savefig(tmp, dpi=100)
    os.replace(tmp, os.path.join(out, "tradeoff.png"))


if __name__ == "__main__":
    main()
