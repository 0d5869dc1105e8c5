#!/usr/bin/env python3
"""Writes the catalogues of portals other than the thesis's, from scenarios/catalogue.toml.

Everything the built-in catalogue says about subjects, objects, materials, noise and the
physics model is kept; what a portal changes is written here:

- scenarios/portal-front-back.toml: the built-in portal plus an MMW camera behind the
  subject (upper and lower views of the back, mirrored). Its regions are the built-in 13 on
  the front, then 6 on the back (the back zones of the Kaggle/DHS Passenger Screening
  Challenge's 17 that a carried object fits). The metal detector is the built-in one; a back
  region's influence rows are those of the built-in region at the same height and side.

- tests/portals/portal-20x33.toml: a test portal that exercises every count: front and back
  MMW views, a second IR camera (the back's), 20 regions (the front-back portal's 19 and the
  back of the neck) and a 33-zone metal detector (the zone count of the Garrett PD 6500i,
  thesis appendix C). Its zone layout and tables are made up for the test, not fitted to
  any detector: the influence table is tools/metal_table.py's model at 33 zone heights.

Usage: tools/portal_catalogues.py [--check]   (--check: exit 1 where a file is not current)
"""
import math
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import metal_table  # noqa: E402  (the influence model: S, SIGMA)

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

def view_entry(name, camera, size, field, pooled, note="", extra=()):
    """A back [[views]] entry; `extra`: lines of its own camera's numbers."""
    lines = ["[[views]]", 'name = "%s"' % name + ("   # " + note if note else ""), 'camera = "%s"' % camera,
             'side = "back"', "size = [%d, %d]" % size, "field = [%s]" % ", ".join(str(v) for v in field)]
    return "\n" + "\n".join(lines + (["pooled = true"] if pooled else []) + list(extra)) + "\n"


TWIN = "a second %s camera behind the subject: assumed the front one's twin"
BACK_VIEWS = (view_entry("back_upper", "mmw", (200, 200), (0, 0, 200, 200), True, TWIN % "MMW") +
              view_entry("back_lower", "mmw", (200, 200), (0, 200, 200, 200), True))
# The test portal's back MMW camera is another make, with a coarser raw grid of its own
# ([[views]] raw, over the run's --mmw-raw): assumed, for the test.
OWN_RAW = ["raw = [24, 24]      # its own raw grid (assumed: another make than the front's)"]
BACK_VIEWS_OWN_RAW = (view_entry("back_upper", "mmw", (200, 200), (0, 0, 200, 200), True,
                                 "a second MMW camera behind the subject", OWN_RAW) +
                      view_entry("back_lower", "mmw", (200, 200), (0, 200, 200, 200), True, "", OWN_RAW))
BACK_IR_VIEW = view_entry("back_ir", "ir", (100, 200), (0, 0, 200, 400), False, TWIN % "IR")

# name, rects (a back view is mirrored: the subject's right on its right), and the built-in
# region (1-based) whose influence rows it takes: the one at the same height and side.
BACK_REGIONS = [
    ("upper-back", {"back_upper": [66, 40, 68, 70], "back_ir": [33, 20, 34, 35]}, 2),
    ("lower-back", {"back_upper": [70, 110, 60, 56], "back_ir": [35, 55, 30, 28]}, 5),
    ("back-waistband", {"back_upper": [62, 168, 76, 30], "back_ir": [31, 84, 38, 15]}, 5),
    ("seat", {"back_lower": [54, 2, 92, 60], "back_ir": [27, 101, 46, 30]}, 8),
    ("back-of-right-knee", {"back_lower": [104, 80, 46, 55], "back_ir": [52, 140, 23, 28]}, 10),
    ("back-of-left-knee", {"back_lower": [50, 80, 46, 55], "back_ir": [25, 140, 23, 28]}, 11),
]
NECK = ("back-of-neck", {"back_upper": [82, 6, 36, 30], "back_ir": [41, 3, 18, 15]})

ZONES_33 = 33


def between(text, begin, end):
    """(start, stop) of text[begin marker .. end marker), both markers required."""
    a = text.index(begin)
    return a, text.index(end, a)


def rect_line(rects, views):
    return "rects = { " + ", ".join("%s = [%s]" % (v, ", ".join(str(x) for x in r))
                                    for v, r in rects.items() if v in views) + " }"


def builtin_regions(text):
    """The built-in catalogue's [[regions]] as (name, rects line)."""
    a, b = between(text, "[[regions]]", "# --- Objects")
    out = []
    for block in text[a:b].split("[[regions]]")[1:]:
        lines = [l for l in block.strip().splitlines() if l.strip()]
        name = lines[0].split("=", 1)[1].strip().strip('"')
        out.append((name, lines[1]))
    return out


def influence_rows(text):
    """{category: [row per built-in region]} from the built-in [metal.influence]."""
    a, b = between(text, "[metal.influence]", "# END metal table")
    rows, cat = {}, None
    for line in text[a:b].splitlines()[1:]:
        if line.endswith("= ["):
            cat = line.split("=")[0].strip()
            rows[cat] = []
        elif line.strip().startswith("["):
            rows[cat].append([int(v) for v in line.split("]")[0].strip(" [").split(",")])
    return rows


def regions_section(front, back, views, intro):
    out = [intro]
    for name, rects in front:
        out += ["[[regions]]", 'name = "%s"' % name, rects, ""]
    for name, rects in back:
        out += ["[[regions]]", 'name = "%s"' % name, rect_line(rects, views), ""]
    return "\n".join(out) + "\n"


def table_section(zones, regions, rows, about):
    """[metal]'s generated part: zone count, categories, influence rows (one per region)."""
    out = ["# BEGIN metal table: generated by tools/portal_catalogues.py (see its docstring)",
           "[metal]",
           "zones = %d" % zones,
           "categories = [" + ", ".join('"%s"' % c for c in metal_table.CATEGORIES) + "]"]
    out += ["# " + l for l in about]
    out.append("[metal.influence]")
    for c in metal_table.CATEGORIES:
        out.append("%s = [" % c)
        for r, (row, note) in enumerate(rows[c]):
            out.append("  [" + ", ".join("%3d" % v for v in row) + "],  # region %d%s" % (r + 1, note))
        out.append("]")
    out.append("# END metal table")
    return "\n".join(out) + "\n"


def header(lines):
    return "".join("# %s\n" % l if l else "#\n" for l in lines)


def replace_span(text, begin, end, new, keep_end=True):
    a, b = between(text, begin, end)
    return text[:a] + new + text[b if keep_end else b + len(end):]


def views_with(text, back_mmw, back_ir=""):
    """The built-in views with the back MMW views before the IR view and `back_ir` after it."""
    a = text.index('[[views]]\nname = "ir"')
    b = text.index("# --- The physics model", a)
    ir = text[a:b].rstrip("\n") + "\n"
    return text[:a] + back_mmw.lstrip("\n") + "\n" + ir + back_ir + "\n" + text[b:]


def front_back(text):
    regions = builtin_regions(text)
    infl = influence_rows(text)
    views = ["upper", "lower", "back_upper", "back_lower", "ir"]
    out = header([
        "A portal with front AND back MMW views (scenarios/portal-front-back.toml): the built-in",
        "portal's cameras, plus an MMW camera behind the subject (upper and lower views of the",
        "body's back), and a body that carries objects on its back as well as its front.",
        "Written by tools/portal_catalogues.py from scenarios/catalogue.toml: everything but the",
        "views, the regions and the metal table's rows is the built-in catalogue's.",
        "A gun on the upper back (region 14):",
        "  portalsim simulate --catalogue scenarios/portal-front-back.toml \\",
        "    none none none none none none none none none none none none none gun",
    ])
    body = text[text.index("format = 1"):]
    body = views_with(body, BACK_VIEWS)
    body = replace_span(body, "# --- Regions", "# --- Objects", regions_section(regions, [(n, r) for n, r, _ in BACK_REGIONS], views, "\n".join([
        "# --- Regions: the built-in 13 on the front (1-13, as the thesis's command line numbers",
        "# them), then 6 on the back (14-19: the back regions of the Kaggle/DHS Passenger",
        "# Screening Challenge's 17 zones that a carried object fits). rects gives the region's",
        "# rectangle in each view that sees it, [x, y, width, height] in that view's pixels; a",
        "# back view is mirrored, so the subject's right is on its right. The IR camera sees the",
        "# front only."])))
    rows = {c: [(infl[c][r], "") for r in range(len(regions))] +
            [(infl[c][src - 1], " (%s: the built-in's %d)" % (name, src)) for name, _, src in BACK_REGIONS]
            for c in metal_table.CATEGORIES}
    about = ["influence.<category> has one row per region, one value per zone; the output is",
             "clamp(base - sum of influences, 1, 200). Rows 1-13 are the built-in table",
             "(tools/metal_table.py). A back region's row is the built-in region's at the same",
             "height and side (named beside it): assumed, since a walk-through detector's coils",
             "respond to an object's height and lateral place, not to which side of the body it",
             "is on (thesis appendix C tabulates front regions only)."]
    body = replace_span(body, "# BEGIN metal table", "# END metal table\n",
                        table_section(19, len(rows["none"]), rows, about), keep_end=False)
    return out + body


def zone_layout_33():
    """Panel, height fraction (0 head, 1 floor) per zone: 17 on A, 16 on B, evenly spaced."""
    panel = ["A"] * 17 + ["B"] * 16
    height = [0.03 + 0.94 * k / 16 for k in range(17)] + [0.06 + 0.88 * k / 15 for k in range(16)]
    return panel, height


def region_place(text_regions, views_field):
    """Each region's centre: height fraction of the field and side (0 right .. 1 left)."""
    out = []
    for rects in text_regions:
        view, (x, y, w, h) = next(iter(rects.items()))
        fx, fy, fw, fh, sw, sh, back = views_field[view]
        col = fx + (x + w / 2) * fw / sw
        row = fy + (y + h / 2) * fh / sh
        if back:
            col = fx + fw - (x + w / 2) * fw / sw
        out.append((row / 400.0, col / 200.0))
    return out


def parse_rects(line):
    body = line.split("{", 1)[1].rsplit("}", 1)[0]
    out = {}
    for part in body.split("],"):
        part = part.strip().rstrip("]")
        if not part:
            continue
        v, r = part.split("=")
        out[v.strip()] = [int(x) for x in r.strip(" [").split(",")]
    return out


def portal_20x33(text):
    regions = builtin_regions(text)
    views = ["upper", "lower", "back_upper", "back_lower", "ir", "back_ir"]
    fields = {"upper": (0, 0, 200, 200, 200, 200, False), "lower": (0, 200, 200, 200, 200, 200, False),
              "back_upper": (0, 0, 200, 200, 200, 200, True), "back_lower": (0, 200, 200, 200, 200, 200, True)}
    back = [(n, r) for n, r, _ in BACK_REGIONS] + [NECK]
    all_rects = [{k: v for k, v in parse_rects(line).items() if k in fields} for _, line in regions] + \
                [{k: v for k, v in r.items() if k in fields} for _, r in back]
    places = region_place(all_rects, fields)
    panel, zh = zone_layout_33()

    def raw(c, r, z):
        h, side = places[r]
        far = side if panel[z] == "A" else 1.0 - side
        dh = h - zh[z]
        return metal_table.S[c] * (1.0 - 0.25 * far) * math.exp(-dh * dh / (2 * metal_table.SIGMA ** 2))

    rows = {c: [([min(199, int(math.floor(raw(c, r, z) + 0.5))) for z in range(ZONES_33)], "")
                for r in range(len(places))] for c in metal_table.CATEGORIES}
    out = header([
        "A test portal (tests/portals/portal-20x33.toml), written by tools/portal_catalogues.py",
        "from scenarios/catalogue.toml: front and back MMW views, front and back IR views, 20",
        "regions and a 33-zone metal detector. It exercises the counts a catalogue may declare;",
        "its coil layout and tables are made up (assumed, see the tool's docstring), not a",
        "detector's.",
    ])
    body = text[text.index("format = 1"):]
    body = views_with(body, BACK_VIEWS_OWN_RAW, BACK_IR_VIEW)
    body = replace_span(body, "# --- Regions", "# --- Objects", regions_section(regions, back, views, "\n".join([
        "# --- Regions: the built-in 13 on the front, then 7 on the back; each back region is",
        "# seen by a back MMW view and the back IR view."])))
    about = ["influence.<category>: tools/metal_table.py's model (S, SIGMA, the far side's 0.75)",
             "at 33 zone heights, 17 on panel A and 16 on B, evenly spaced: assumed, for the test."]
    body = replace_span(body, "# BEGIN metal table", "# END metal table\n",
                        table_section(ZONES_33, len(places), rows, about), keep_end=False)
    # Subjects: each its built-in base zones' lowest value in every zone.
    lines = body.split("\n")
    for i, l in enumerate(lines):
        if l.startswith("base_zones = ["):
            low = min(int(v) for v in l.split("[", 1)[1].rstrip("]").split(","))
            lines[i] = "base_zones = [" + ", ".join([str(low)] * ZONES_33) + "]"
    body = "\n".join(lines)
    fmt = lambda v: ", ".join("%.4f" % x for x in v)
    body_height = 1.75
    tx = [body_height * (1.0 - h) for h in zh]
    rx = [min(2.1, max(0.0, t + (0.1 if z % 2 else -0.1))) for z, t in enumerate(tx)]
    physics = "\n".join([
        "# The 33 zones' coils, assumed for the test: zones 1-17 transmit on panel A, 18-33 on",
        "# B, at evenly spaced heights, each receiving 0.1 m above or below on the other panel;",
        "# one gain for all.",
        "tx_panel = [" + ", ".join('"a"' if p == "A" else '"b"' for p in panel) + "]",
        "tx_height = [%s]" % fmt(tx),
        "rx_height = [%s]" % fmt(rx),
        "gain = [%s]" % ", ".join(["1.0"] * ZONES_33),
        ""])
    body = replace_span(body, "# The panel each zone's coil transmits from", "# Mean magnetic polarizability", physics)
    return out + body


def main():
    check = "--check" in sys.argv[1:]
    text = open(os.path.join(ROOT, "scenarios", "catalogue.toml")).read()
    stale = []
    for rel, make in (("scenarios/portal-front-back.toml", front_back), ("tests/portals/portal-20x33.toml", portal_20x33)):
        path = os.path.join(ROOT, rel)
        new = make(text)
        old = open(path).read() if os.path.exists(path) else None
        if new == old:
            continue
        if check:
            stale.append(rel)
            continue
        os.makedirs(os.path.dirname(path), exist_ok=True)
        with open(path + ".tmp", "w") as f:
            f.write(new)
        os.replace(path + ".tmp", path)
        print("wrote", rel)
    if stale:
        print("not current (run tools/portal_catalogues.py): " + ", ".join(stale), file=sys.stderr)
        sys.exit(1)


if __name__ == "__main__":
    main()
