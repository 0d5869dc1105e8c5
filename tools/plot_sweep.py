#!/usr/bin/env python3
"""The plot of `portalsim evaluate --sweep` (embedded in the binary): from OUT/sweep.json
and OUT/sweep.csv, STAGE/sweep.png: Pd at each target Pfa (rows) against each knob of the
sweep (columns), one colour per sensor and fusion. Each dot is one point of the sweep; the
line joins, for each value of the knob, the mean over the sweep's other settings.
Usage: plot_sweep.py OUT STAGE"""
import csv
import json
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

out, stage = sys.argv[1], sys.argv[2]
definition = json.load(open(os.path.join(out, "sweep.json")))
rows = list(csv.DictReader(open(os.path.join(out, "sweep.csv"))))
knobs = [k for k in rows[0].keys() if k not in ("point", "entry") and not k.startswith(("auc", "pd_"))]
targets = [k[len("pd_at_pfa_"):] for k in rows[0].keys() if k.startswith("pd_at_pfa_")]
entries = list(dict.fromkeys(r["entry"] for r in rows))


def value(text):
    """A knob's value as a number where it is one (16x16 -> 16, the grid's width)."""
    try:
        return float(text)
    except ValueError:
        try:
            return float(text.split("x")[0])
        except ValueError:
            return text


fig, axes = plt.subplots(len(targets), len(knobs), figsize=(4.6 * len(knobs) + 1.5, 3.6 * len(targets)),
                         squeeze=False)
palette = plt.get_cmap("tab10")
for ti, t in enumerate(targets):
    for ki, knob in enumerate(knobs):
        ax = axes[ti][ki]
        for ei, entry in enumerate(entries):
            mine = [r for r in rows if r["entry"] == entry]
            xs = [value(r[knob]) for r in mine]
            ys = [float(r["pd_at_pfa_" + t]) for r in mine]
            style = "-" if not entry.startswith("fused_") else "--"
            ax.plot(xs, ys, "o", color=palette(ei % 10), ms=3, alpha=0.35)
            means = {}
            for x, y in zip(xs, ys):
                means.setdefault(x, []).append(y)
            if all(isinstance(x, float) for x in means):
                keys = sorted(means)
                ax.plot(keys, [sum(means[k]) / len(means[k]) for k in keys], style, color=palette(ei % 10), lw=1.5,
                        label=entry)
        ax.set_xlabel(knob + (" (raw grid width)" if knob == "mmw_raw" else ""))
        ax.set_ylabel("Pd at Pfa %g%%" % (100 * float(t)))
        ax.set_ylim(0, 1.02)
        ax.grid(alpha=0.3)
axes[0][-1].legend(loc="center left", bbox_to_anchor=(1.02, 0.5), fontsize=8)
fig.suptitle("Sweep of %d settings: %s (dots: points; lines: mean over the other knobs' settings)" %
             (len(definition["points"]), definition["sweep"]))
fig.tight_layout()
fig.savefig(os.path.join(stage, "sweep.png"), dpi=100)
