#!/usr/bin/env python3
"""Draws metal_map.png from metal_map.json, one column per orientation of the test object:
on top its probability of detection per cell of the aperture (lateral position across, height
up) at the operating sensitivity; below, its peak response (counts, log scale, before the cap
of 199) with the line where it reaches the operating level's alarm. The two panels and their
coils are drawn, cells the object cannot reach are grey and the critical position is marked.
Usage: plot_metal_map.py DIR   (reads DIR/metal_map.json, writes DIR/metal_map.png)"""
import json
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402


def main(folder):
    with open(os.path.join(folder, "metal_map.json"), encoding="utf-8") as f:
        r = json.load(f)
    xs, zs = np.array(r["grid"]["x_m"]), np.array(r["grid"]["z_m"])
    step = r["grid"]["step_m"]
    coils = r["coils"]
    ax_a, ax_b = coils["panel_a_x_m"], coils["panel_b_x_m"]
    fig, grid = plt.subplots(2, 3, figsize=(13, 11), sharex=True, sharey=True, constrained_layout=True)
    viridis = plt.get_cmap("viridis").copy()
    viridis.set_bad("#d9d9d9")
    magma = plt.get_cmap("magma").copy()
    magma.set_bad("#d9d9d9")
    extent = (xs[0] - step / 2, xs[-1] + step / 2, zs[0] - step / 2, zs[-1] + step / 2)
    level = r["threshold"]["sensitivity"]
    pd_image = response_image = None
    for column, o in enumerate(r["orientations"]):
        pd = np.array([[np.nan if v is None else v for v in row] for row in o["pd"]], dtype=float)
        peak = np.array([[np.nan if v is None else max(v, 1e-3) for v in row] for row in o["peak_response"]],
                        dtype=float)
        top, bottom = grid[0][column], grid[1][column]
        pd_image = top.imshow(np.ma.masked_invalid(pd), origin="lower", extent=extent, cmap=viridis, vmin=0, vmax=1,
                              aspect="auto", interpolation="nearest")
        response_image = bottom.imshow(np.ma.masked_invalid(np.log10(peak)), origin="lower", extent=extent,
                                       cmap=magma, vmin=-1, vmax=4, aspect="auto", interpolation="nearest")
        if level > 0 and np.nanmax(peak) > 200 - level > np.nanmin(peak):
            bottom.contour(xs, zs, np.log10(peak), levels=[np.log10(200 - level)], colors="white", linewidths=1.5)
        for ax in (top, bottom):
            # The panels, and each zone's coils on them: transmit (triangles into the portal), receive (dots).
            for x in (ax_a, ax_b):
                ax.axvspan(x - 0.02 if x < 0 else x, x if x < 0 else x + 0.02, color="#555555")
            for zone in range(19):
                a_side = zone < 9
                tx_x, rx_x = (ax_a, ax_b) if a_side else (ax_b, ax_a)
                ax.plot(tx_x, coils["tx_height_m"][zone], marker=">" if a_side else "<", color="#d62728", ms=6,
                        clip_on=False)
                ax.plot(rx_x, coils["rx_height_m"][zone], marker="o", color="#ff9896", ms=4, clip_on=False)
            c = r["critical"]
            if c and c["orientation"] == o["axis"]:
                ax.plot(c["position"]["x_m"], c["position"]["z_m"], marker="x", color="white", ms=12, mew=3)
                ax.plot(c["position"]["x_m"], c["position"]["z_m"], marker="x", color="#1f77b4", ms=10, mew=1.5)
            ax.set_xlim(ax_a - 0.03, ax_b + 0.03)
            ax.set_ylim(0, max(zs[-1] + step / 2, max(coils["tx_height_m"] + coils["rx_height_m"])) + 0.03)
        ratio = o["sensitivity_ratio"]
        top.set_title("long axis along %s (%s)\nmean Pd %.2f" % (
            o["axis"], {"x": "across", "y": "along the walk", "z": "up"}[o["axis"]], o["mean_pd"]), fontsize=10)
        bottom.set_title("peak response; most / least sensitive cell %s" % (
            "-" if ratio is None else "%.3g" % ratio), fontsize=10)
        bottom.set_xlabel("lateral position x, m (panel A left, panel B right)")
    for row in grid:
        row[0].set_ylabel("height z, m")
    fig.colorbar(pd_image, ax=grid[0], shrink=0.8, label="probability of detection (%d passes)" % r["passes"])
    fig.colorbar(response_image, ax=grid[1], shrink=0.8,
                 label="log10 peak response, counts (white line: alarms at sensitivity %d)" % level)
    th = r["threshold"]
    fig.suptitle("%s walked through at %.2g m/s, read at %.3g Hz: Pd per cell at sensitivity %d (clean testers alarm "
                 "%.3g, Pfa %.3g)\ngrey: the object does not fit there; x: critical position; > <: transmit coils, "
                 "o: receive coils" % (r["object"], r["walk"]["speed_m_per_s"], r["walk"]["sample_rate_hz"],
                                       th["sensitivity"], th["clean_false_alarm_rate"], th["pfa"]), fontsize=11)
    fig.savefig(os.path.join(folder, "metal_map.png"), dpi=80)


if __name__ == "__main__":
    main(sys.argv[1])
