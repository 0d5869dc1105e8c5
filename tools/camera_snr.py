#!/usr/bin/env python3
"""Body against room in the physics model's MMW views, in units of the noise's standard
deviation, as the issue measured it on `simulate --model physics none none none gun`.

    /usr/bin/python3 tools/camera_snr.py build/portalsim [KNOB=VALUE ...]

Masks come from the same scenario without sensor noise (--netd 0), shown through a fixed
window: pixels below the midpoint of its darkest and brightest levels are room, above it
body, each kept only where its whole 21 x 21 neighbourhood is on the same side (the PSF's
blur and the interpolation leave the outline out). The signal is the mean of the body
less the mean of the room in the noisy image (seed 1); the noise is the standard deviation
of the difference of two seeds' images over both masks, over sqrt(2).
"""
import subprocess
import sys
import tempfile
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
from scipy.ndimage import minimum_filter

OBJECTS = ["none", "none", "none", "gun"]


def simulate(portalsim, out, seed, knobs):
    cmd = [portalsim, "simulate", "--model", "physics", "--seed", str(seed), *OBJECTS, "--out", str(out)]
    for k in knobs:
        key, _, value = k.partition("=")
        cmd += ["--" + key.replace("_", "-"), value]
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
    return {v: np.round(plt.imread(out / f"{v}.png") * 255).astype(float) for v in ["upper", "lower"]}


def snr(portalsim, knobs):
    work = Path(tempfile.mkdtemp(prefix="snr_"))
    try:
        clean = simulate(portalsim, work / "clean", 1,
                         ["netd=0", "window=285..305", "frames=1", "display_filter=bilinear", "smooth=0"])
    except subprocess.CalledProcessError:  # a portalsim from before the camera's knobs
        clean = simulate(portalsim, work / "clean", 1, ["netd=0"])
    a = simulate(portalsim, work / "a", 1, knobs)
    b = simulate(portalsim, work / "b", 2, knobs)
    out = {}
    for v in ["upper", "lower"]:
        c = clean[v]
        body = c > (c.min() + c.max()) / 2
        inner_body = minimum_filter(body.astype(np.uint8), size=21) == 1
        inner_room = minimum_filter((~body).astype(np.uint8), size=21) == 1
        signal = a[v][inner_body].mean() - a[v][inner_room].mean()
        both = inner_body | inner_room
        noise = (a[v] - b[v])[both].std() / np.sqrt(2)
        out[v] = (signal, noise, signal / noise)
    return out


if __name__ == "__main__":
    for view, (s, n, r) in snr(sys.argv[1], sys.argv[2:]).items():
        print(f"{view}: body - room {s:.1f} gray levels, noise sd {n:.1f}, ratio {r:.2f}")
