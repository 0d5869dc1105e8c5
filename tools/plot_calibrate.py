#!/usr/bin/env python3
"""calibrate's plot: the captures against the fitted camera, from FOLDER/report.json.

Rows: the catalogue's MMW views (upper and lower in the built-in portal), each titled with
its own raw grid and NETD. Columns: gray-level histograms, noise power spectra
along rows, and the mean profile across the body's left outline. Writes FOLDER/calibrate.png.
"""
import json
import pathlib
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def main() -> int:
    folder = pathlib.Path(sys.argv[1])
    report = json.loads((folder / "report.json").read_text())
    stats, fit = report["statistics"], report["fit"]
    # Each view's own camera: its raw grid, and the NETD generate gives it. The rows follow
    # the catalogue's order (the statistics' keys are sorted by name).
    own = {v["name"]: v for v in fit.get("views", [])}
    views = [name for name in own if name in stats] or list(stats)
    fig, axes = plt.subplots(len(views), 3, figsize=(13, 3.6 * len(views)), squeeze=False)
    for row, view in zip(axes, views):
        s = stats[view]
        for key, style in (("real", dict(color="k", lw=1.6, label="captures")),
                           ("sim", dict(color="tab:red", lw=1.1, ls="--", label="fitted camera"))):
            row[0].plot(range(256), s["histogram"][key], **style)
            nps = s["noise_power"][key]
            row[1].semilogy([f / (2 * (len(nps) - 1)) for f in range(len(nps))], [max(v, 1e-6) for v in nps], **style)
            prof = s["edge_profile"][key]
            x0 = s["edge_profile"]["offset_from"]
            row[2].plot([x0 + i for i in range(len(prof))], [float("nan") if v is None else v for v in prof], **style)
        camera = ""
        if view in own:
            v = own[view]
            grid = v["camera"]["raw_grid"]
            camera = f" ({grid['width']}x{grid['height']}, NETD {v['camera']['netd']:.3f} K)"
        row[0].set(title=f"{view}{camera}: gray-level histogram", xlabel="gray level", ylabel="fraction of pixels")
        row[1].set(title=f"{view}: noise power along rows", xlabel="cycles per pixel", ylabel="gray^2 per bin")
        row[2].set(title=f"{view}: across the body's left outline", xlabel="pixels from the edge",
                   ylabel="mean gray level")
        for ax in row:
            ax.grid(alpha=0.3)
            ax.legend(fontsize=8)
    differ = any(v["own_raw"] or v["own_netd"] for v in own.values())
    runs = " (the run's; each view's in its row)" if differ else ""
    fig.suptitle(f"raw grid {fit['raw_grid']['width']}x{fit['raw_grid']['height']}{runs}, "
                 f"PSF FWHM {fit['psf_fwhm_pixels']:.2f} px, window {fit['display_min']:.2f}..{fit['display_max']:.2f} K, "
                 f"NETD {fit['netd']:.3f} K ({fit['captures']} captures)")
    fig.tight_layout()
    fig.savefig(folder / "calibrate.png", dpi=90)
    return 0


if __name__ == "__main__":
    sys.exit(main())
