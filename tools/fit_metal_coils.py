#!/usr/bin/python3
"""Fits the physics model of the walk-through metal detector and writes [metal.physics]
in scenarios/catalogue.toml (between the "metal physics" markers).

The model (docs/model/metal.md; host/backend/reference/metal_physics.cpp):

- Portal coordinates in metres: x across the portal (panel A, the subject's right, at
  x = -separation/2; panel B at +separation/2), y along the walk (0: every coil and object
  sits in the portal's mid-plane), z up from the floor.
- Zone z (1-9 on panel A, 10-19 on panel B) is a transmit coil on its own panel at height
  tx_height[z] and a receive coil on the other panel at rx_height[z]: magnetic dipoles of
  moments tx_moment and rx_moment along x, pointing into the portal.
- An object at p with polarizability tensor M gives H_R(p)^T M H_T(p), with the dipole
  field H(p) = (3 (m.r) r / |r|^2 - m) / (4 pi |r|^3), r = p - coil. Objects add.
- A zone deducts D = round(gain[z] * |sum|) (half up, at most 199) from the subject's
  base value; the value is clamp(base - D, 1, 200) (thesis: base 200 for subject 1).
  gain[z] is the zone's own sensitivity: the PD 6500i sets a sensitivity per zone, and
  each zone's receive channel has its own amplifier. Bounded to GAIN_SPREAD either side
  of its panel's geometric mean.
- M = m_c * 3 / (a + 2) * (I + (a - 1) u u^T): mean polarizability m_c of the object's
  metal category, anisotropy a along the drawing's long axis u (x for "h" or a single
  drawing, z for "v"). The anisotropy is the object's metal_anisotropy (1: isotropic).
- Object position: its region's rectangle centre in its MMW view; the two MMW views
  stacked span body_height (upper view on top), x centred on the view.
- An object is SEGMENTS equal dipoles (M / SEGMENTS each) at the midpoints of equal
  segments of its drawn long side (the sprite's longer side, in metres; x for a drawing
  wider than tall, z otherwise, the "v" variant turned): the coils' fields change by a
  factor of 2-3 over a 25 cm rod, which one point at its centre cannot follow.

Fitted, by least squares: the 19 transmit and 19 receive heights, the 19 zone gains and
the polarizabilities of trace, small, medium and large metal, to the thesis's three worked
examples (section 4.3.3 and the gun of 4.4.1), with the existing thesis table's cells as
soft constraints (weight SOFT). Only gain * polarizability is identified, so heavy is
held at HEAVY_CM3 as the scale. A zone the thesis saturates (value 1) counts only where
the model falls short of 199; elsewhere the residual is on the unclamped deduction, so a
zone the model saturates still has a gradient. Residuals are reported on the integer
zones the C++ gives, in the fit and with each example left out of it (its table cells
too): the left-out example is then a prediction.

Usage: /usr/bin/python3 tools/fit_metal_coils.py [--loo] [scenarios/catalogue.toml]
  (Debian's numpy/scipy); --loo adds the leave-one-example-out residuals to the report.
"""
import math
import os
import sys
import tomllib

import numpy as np
from scipy.optimize import least_squares

BODY_HEIGHT = 1.75  # m, an adult; the two MMW views stacked
SEPARATION = 0.76  # m, Garrett PD 6500i passage width (30 in)
TX_MOMENT = 1.0  # A m^2; only gain * tx_moment * rx_moment is identified
RX_MOMENT = 1.0
HEAVY_CM3 = 100.0  # the scale anchor (see above)
GAIN_SPREAD = 10.0  # a zone's gain within this factor of its panel's geometric mean
SOFT = 0.05  # weight of a thesis-table cell against a worked example's zone
PANEL_A_ZONES = 9
MAX_NFEV = 400
FIT_CATEGORIES = ["trace", "small", "medium", "large"]
SEGMENTS = 5  # dipoles along an object's long side (kernels/contract.h PS_METAL_SEGMENTS)

GUN = [193, 112, 75, 2, 1, 1, 96, 200, 200, 190, 196, 53, 53, 94, 64, 82, 53, 200, 200]
PIPE = [197, 131, 108, 88, 95, 106, 192, 200, 200, 197, 199, 54, 54, 75, 44, 84, 137, 200, 200]
PHONE_DISK = [200, 183, 165, 136, 137, 142, 193, 200, 200, 198, 199, 185, 185, 195, 176, 175, 190, 200, 200]


def load(path):
    with open(path, "rb") as f:
        return tomllib.load(f)


def region_positions(cat):
    """Region r's centre in portal coordinates (x, z), metres: in the portal's 200 x 400 field
    (host/scene/sensor.h), as the first view that sees it frames it (a back view mirrored)."""
    scale = BODY_HEIGHT / 400.0
    views = {v["name"]: v for v in cat["views"]}
    pos = {}
    for k, r in enumerate(cat["regions"]):
        v = next(views[name] for name in views if name in r["rects"])
        fx, fy, fw, fh = v["field"]
        (w, h), (x0, y0, rw, rh) = v["size"], r["rects"][v["name"]]
        cx, cy = (x0 + rw / 2.0) * fw / w, (y0 + rh / 2.0) * fh / h
        col = fx + fw - cx if v.get("side") == "back" else fx + cx
        pos[k + 1] = ((col - 100.0) * scale, BODY_HEIGHT - (fy + cy) * scale)
    return pos


def anisotropy(cat, name):
    for o in cat["objects"]:
        if o["name"] == name:
            return o.get("metal_anisotropy", 1.0)
    raise KeyError(name)


def long_side(cat, name, variant=""):
    """The vector (metres, x and z) along a drawing's longer side: an "h" or single drawing
    as drawn, a "v" variant turned a quarter."""
    scale = BODY_HEIGHT / (2.0 * cat["images"]["mmw_height"])
    for o in cat["objects"]:
        if o["name"] == name:
            w, h = o["size"]
            if variant == "v":
                w, h = h, w
            return (w * scale, 0.0) if w >= h else (0.0, h * scale)
    raise KeyError(name)


def tensor(m, a, axis):
    """3x3 polarizability, mean m, anisotropy a along axis 0 (x) or 2 (z)."""
    u = np.zeros(3)
    u[axis] = 1.0
    return m * 3.0 / (a + 2.0) * (np.eye(3) + (a - 1.0) * np.outer(u, u))


def dipole(moment, coil, p):
    """Fields of dipoles (rows of moment, coil) at point p: (n, 3)."""
    r = p[None, :] - coil
    d2 = np.sum(r * r, axis=1)
    d = np.sqrt(d2)
    mr = np.sum(moment * r, axis=1)
    return (3.0 * mr[:, None] * r / d2[:, None] - moment) / (4.0 * math.pi * d2 * d)[:, None]


def zone_signals(tx_h, rx_h, objects):
    """objects: list of (M, (x, z)) or (M, (x, z), (lx, lz)), the last the long side that
    its SEGMENTS dipoles share. Returns the 19 summed signals."""
    side = np.where(np.arange(19) < PANEL_A_ZONES, -1.0, 1.0)
    zero = np.zeros(19)
    tx = np.stack([side * SEPARATION / 2, zero, tx_h], axis=1)
    rx = np.stack([-side * SEPARATION / 2, zero, rx_h], axis=1)
    mt = np.stack([-side * TX_MOMENT, zero, zero], axis=1)
    mr = np.stack([side * RX_MOMENT, zero, zero], axis=1)
    out = np.zeros(19)
    for o in objects:
        M, (x, h) = o[0], o[1]
        lx, lz = o[2] if len(o) > 2 else (0.0, 0.0)
        n = SEGMENTS if len(o) > 2 else 1
        for k in range(n):
            f = (k + 0.5) / n - 0.5
            p = np.array([x + f * lx, 0.0, h + f * lz])
            out += np.sum(dipole(mr, rx, p) * (dipole(mt, tx, p) @ M.T), axis=1) / n
    return out


def deduction(gains, s):
    return np.minimum(gains * np.abs(s), 199.0)


# The thesis table's cells that are the worked examples themselves (tools/metal_table.py
# pins them): left out with their example.
EXAMPLE_CELLS = [[("heavy", 4)], [("large", 3)], [("small", 3), ("trace", 7)]]
NAMES = ["gun in region 4", "iron pipe in region 3", "mobile in region 3 + disk in region 7"]
# Parameter vector: 19 transmit heights, 19 receive heights, 2 panel log-gains, 19 zone
# log-gain offsets from their panel's, 4 log-polarizabilities.
TX, RX, PANEL, OFFSET, POL = slice(0, 19), slice(19, 38), slice(38, 40), slice(40, 59), slice(59, 63)
PANELS = [slice(0, PANEL_A_ZONES), slice(PANEL_A_ZONES, 19)]


class Problem:
    def __init__(self, cat, leave_out=None):
        self.cat = cat
        self.pos = region_positions(cat)
        gun_a = anisotropy(cat, "gun")
        # (list of (category, anisotropy, axis, region, long side), thesis zones)
        examples = [
            ([("heavy", gun_a, 0, 4, long_side(cat, "gun", "h"))], GUN),
            ([("large", anisotropy(cat, "iron-pipe"), 0, 3, long_side(cat, "iron-pipe"))], PIPE),
            ([("small", anisotropy(cat, "mobile-phone"), 0, 3, long_side(cat, "mobile-phone")),
              ("trace", anisotropy(cat, "compact-disk"), 0, 7, long_side(cat, "compact-disk"))], PHONE_DISK),
        ]
        self.examples = examples
        self.fitted = [i for i in range(3) if i != leave_out]
        skip = EXAMPLE_CELLS[leave_out] if leave_out is not None else []
        cats = cat["metal"]["categories"]
        self.table = []  # (category, region, 19 deductions)
        for c in FIT_CATEGORIES + ["heavy"]:
            rows = cat["metal"]["influence"][c]
            for r in range(13):
                if (c, r + 1) not in skip:
                    self.table.append((c, r + 1, np.array(rows[r], dtype=float)))
        assert cats[0] == "none"

    @staticmethod
    def unpack(th):
        gains = np.exp(np.concatenate([th[OFFSET][p] + th[PANEL][i] for i, p in enumerate(PANELS)]))
        pol = {"none": 0.0, "heavy": HEAVY_CM3}
        for i, c in enumerate(FIT_CATEGORIES):
            pol[c] = math.exp(th[POL][i])
        return th[TX], th[RX], gains, pol

    def example_deductions(self, th, ex):
        tx_h, rx_h, gains, pol = self.unpack(th)
        objs = [(tensor(pol[c], a, axis), self.pos[r], side) for c, a, axis, r, side in ex]
        return gains * np.abs(zone_signals(tx_h, rx_h, objs))

    def example_zones(self, th, ex):
        """The integer zones as the C++ computes them."""
        d = np.floor(np.minimum(self.example_deductions(th, ex), 199.0) + 0.5)
        return np.clip(200.0 - d, 1.0, 200.0).astype(int)

    def residuals(self, th):
        res = []
        for i in self.fitted:
            ex, target = self.examples[i]
            want = 200.0 - np.array(target, dtype=float)
            r = self.example_deductions(th, ex) - want
            sat = want >= 199.0  # the thesis's 1: anything at or past the cap
            r[sat] = np.minimum(r[sat], 0.0)
            res.extend(r)
        tx_h, rx_h, gains, pol = self.unpack(th)
        # An isotropic 1 cm^3 object in each region; the table's cells scale it.
        unit = {r: zone_signals(tx_h, rx_h, [(np.eye(3), self.pos[r])]) for r in range(1, 14)}
        for c, r, row in self.table:
            res.extend(SOFT * (deduction(gains, pol[c] * unit[r]) - row))
        # Each panel's offsets average to zero, so the panel gain is their geometric mean.
        res.extend([np.mean(th[OFFSET][p]) for p in PANELS])
        return np.array(res)


# Bounds: heights within the portal (0 to 2.1 m), gains and polarizabilities positive,
# each zone's gain within GAIN_SPREAD of its panel's.
SPREAD = math.log(GAIN_SPREAD)
LO = np.concatenate([np.full(38, 0.0), np.full(2, -20.0), np.full(19, -SPREAD), np.full(4, math.log(0.01))])
HI = np.concatenate([np.full(38, 2.1), np.full(2, 20.0), np.full(19, SPREAD), np.full(4, math.log(1000.0))])


def current(problem):
    """The catalogue's [metal.physics] as a parameter vector, or None: refits start there."""
    mp = problem.cat["metal"].get("physics")
    if not mp:
        return None
    pol = mp["polarizability"]
    g = np.log(np.array(mp["gain"], dtype=float))
    if len(g) == 2:  # the panel gains of the model before per-zone gains
        g = np.repeat(g, [PANEL_A_ZONES, 19 - PANEL_A_ZONES])
    panel = [np.mean(g[p]) for p in PANELS]
    offset = np.concatenate([g[p] - panel[i] for i, p in enumerate(PANELS)])
    return np.concatenate([mp["tx_height"], mp["rx_height"], panel, offset,
                           [math.log(max(pol[c], 1e-3)) for c in FIT_CATEGORIES]])


def solve(problem, th0):
    return least_squares(problem.residuals, np.clip(th0, LO + 1e-9, HI - 1e-9), bounds=(LO, HI), x_scale="jac",
                         max_nfev=MAX_NFEV)


def fit(problem, start=None):
    """From `start` alone, or else from the catalogue's values and a thesis-like guess: the better."""
    if start is not None:
        return solve(problem, start).x
    best = None
    start = current(problem)
    if start is not None:
        best = solve(problem, start)
    base_h = np.array([1.55, 1.40, 1.30, 1.15, 1.05, 0.95, 0.75, 0.45, 0.15,
                       1.65, 1.55, 1.40, 1.30, 1.15, 1.05, 0.95, 0.75, 0.45, 0.15])
    th0 = np.concatenate([base_h, base_h, [math.log(2.0), math.log(2.0)], np.zeros(19),
                          [math.log(v) for v in (8.0, 20.0, 40.0, 70.0)]])
    r = solve(problem, th0)
    if best is None or r.cost < best.cost:
        best = r
    return best.x


def rounded(th):
    """The parameters as written to the catalogue (so residuals are the catalogue's)."""
    out = th.copy()
    out[0:38] = np.round(th[0:38], 4)
    g = np.array([float("%.6g" % v) for v in Problem.unpack(th)[2]])
    lg = np.log(g)
    out[PANEL] = [np.mean(lg[p]) for p in PANELS]
    out[OFFSET] = np.concatenate([lg[p] - out[PANEL][i] for i, p in enumerate(PANELS)])
    out[POL] = np.log(np.array([float("%.5g" % v) for v in np.exp(th[POL])]))
    return out


def section(problem, th):
    tx_h, rx_h, gains, pol = problem.unpack(th)
    fmt = lambda v: ", ".join("%.4f" % x for x in v)
    lines = [
        "# BEGIN metal physics: generated by tools/fit_metal_coils.py (see its docstring for the model)",
        "# --model physics: zones from coil fields and object polarizability (Marsh et al.,",
        "# Meas. Sci. Technol. 25:055107, 2014: signal H_R^T M H_T, dipole coils, objects add).",
        "[metal.physics]",
        "body_height = %.4f       # m, assumed adult; the two MMW views stacked span it" % BODY_HEIGHT,
        "panel_separation = %.4f  # m, Garrett PD 6500i passage width (30 in), appendix C" % SEPARATION,
        "tx_moment = %.4f         # A m^2, along x into the portal; only gain * moments is identified" % TX_MOMENT,
        "rx_moment = %.4f" % RX_MOMENT,
        "# The panel each zone's coil transmits from: \"a\" (x < 0, the subject's right) or \"b\"; each",
        "# receives on the other panel. Assumed: the thesis gives no coil layout; zones 1-9 on A and",
        "# 10-19 on B is tools/metal_table.py's model of the influence table's two column groups.",
        "tx_panel = [%s]" % ", ".join('"a"' if z < PANEL_A_ZONES else '"b"' for z in range(19)),
        "# Coil heights above the floor, m, zones 1-19. Fitted.",
        "tx_height = [%s]" % fmt(tx_h),
        "rx_height = [%s]" % fmt(rx_h),
        "# Counts per unit of |H_R^T M H_T| (H in A/m, M in cm^3), zones 1-19: each zone's own",
        "# sensitivity, within a factor %g of its panel's geometric mean. Fitted." % GAIN_SPREAD,
        "gain = [%s]" % ", ".join("%.6g" % g for g in gains),
        "# Mean magnetic polarizability per metal category, cm^3 (the tensor's trace / 3, Ledger &",
        "# Lionheart). Fitted; heavy is the scale anchor (only gain * polarizability is identified).",
        "[metal.physics.polarizability]",
    ]
    for c in problem.cat["metal"]["categories"]:
        lines.append("%s = %.5g" % (c, pol[c]))
    lines.append("# END metal physics")
    return "\n".join(lines) + "\n"


def rms(res):
    return math.sqrt(np.mean(np.asarray(res, dtype=float) ** 2))


def report(problem, th, loo=None):
    """Per example: the zones, the residuals, their rms and max; with `loo`, the rms of
    each example predicted by the fit without it."""
    print("zone residuals (physics - thesis), integer zones as the C++ computes them:")
    for i, (name, (ex, target)) in enumerate(zip(NAMES, problem.examples)):
        got = problem.example_zones(th, ex)
        res = got - np.array(target)
        print("  %s" % name)
        print("    physics: " + " ".join("%3d" % v for v in got))
        print("    thesis:  " + " ".join("%3d" % v for v in target))
        print("    resid:   " + " ".join("%3d" % v for v in res))
        line = "    rms %.1f, max |%d|" % (rms(res), int(np.max(np.abs(res))))
        if loo is not None:
            line += "; left out of the fit: rms %.1f, max |%d|" % loo[i]
        print(line)
    g = problem.unpack(th)[2]
    print("zone gains / panel geometric mean: " + " ".join("%.2f" % v for v in
          np.concatenate([g[p] / math.exp(np.mean(np.log(g[p]))) for p in PANELS])))


def leave_one_out(cat, th):
    """Each example predicted by a fit to the other two (and the table without its cells)."""
    out = []
    for k in range(3):
        p = Problem(cat, leave_out=k)
        thk = rounded(fit(p, start=th))
        ex, target = p.examples[k]
        res = p.example_zones(thk, ex) - np.array(target)
        out.append((rms(res), int(np.max(np.abs(res)))))
    return out


def write(path, problem, th):
    """Replaces [metal.physics] (between its markers) in the catalogue, all or nothing."""
    text = open(path).read()
    new = section(problem, th)
    if "# BEGIN metal physics" in text:
        begin = text.index("# BEGIN metal physics")
        end = text.index("\n", text.index("# END metal physics")) + 1
        text = text[:begin] + new + text[end:]
    else:
        end = text.index("\n", text.index("# END metal table")) + 1
        text = text[:end] + new + text[end:]
    with open(path + ".tmp", "w") as f:
        f.write(text)
    os.replace(path + ".tmp", path)


def main():
    args = [a for a in sys.argv[1:] if a != "--loo"]
    path = args[0] if args else "scenarios/catalogue.toml"
    cat = load(path)
    problem = Problem(cat)
    th = rounded(fit(problem))
    write(path, problem, th)
    report(problem, th, leave_one_out(cat, th) if "--loo" in sys.argv[1:] else None)


if __name__ == "__main__":
    main()
