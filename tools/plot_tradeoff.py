#!/usr/bin/env python3
"""Draws tradeoff.png from tradeoff.json: throughput against error per fidelity tier,
with the Pareto front (no other tier is both faster and more accurate) marked.
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


def main():
    out = sys.argv[1]
    data = json.load(open(os.path.join(out, "tradeoff.json")))
    rows = data["rows"]
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.5))
    panels = [("features_per_s", "feature_max_abs", "features-only throughput (scenarios/s)",
               "max |feature error| vs fp64 reference"),
              ("images_per_s", "mmw_rmse_mean", "all-sensor image throughput (scenarios/s)",
               "mean per-image MMW RMSE vs fp64 reference (gray levels)")]
    for ax, (xk, yk, xl, yl) in zip(axes, panels):
        pts = [(r[xk], max(r[yk], 1e-7)) for r in rows]
        front = pareto(pts)
        for i, r in enumerate(rows):
            ax.scatter(pts[i][0], pts[i][1], s=70, marker="*" if i in front else "o",
                       color="C3" if i in front else "C0", zorder=3)
            acc = r.get("j48_accuracy")
            label = r["name"] + ("" if acc is None else "\nJ48 %.1f%%" % acc)
            ax.annotate(label, pts[i], textcoords="offset points", xytext=(6, 6), fontsize=8)
        ax.plot([pts[i][0] for i in front], [pts[i][1] for i in front], "--", color="C3", label="Pareto front")
        xs = [p[0] for p in pts]
        if max(xs) > 10 * min(xs):  # a log axis only where the range calls for one
            ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel(xl)
        ax.set_ylabel(yl)
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8)
    fig.suptitle("portalsim fidelity tiers: %d scenarios, %s" % (data["count"], data["machine"]), fontsize=10)
    fig.tight_layout()
    tmp = os.path.join(out, "tradeoff.png.tmp.png")
    fig.savefig(tmp, dpi=110)
    os.replace(tmp, os.path.join(out, "tradeoff.png"))


if __name__ == "__main__":
    main()
