"""Generator.batch is generate --format h5's data.h5, byte for byte, for any batch size."""
import subprocess

import h5py
import numpy as np
import pytest

import portalsim

N = 70  # past one 64-row chunk of data.h5

CASES = {
    "thesis": dict(what="both"),
    "physics-rotated": dict(what="both", model="physics", rotate="-30..30", scale="0.8..1.2", flip=True),
    "thesis-annotations": dict(what="images", annotations=True, objects="1..4", rotate=20, rule="gun"),
    "physics-annotations": dict(what="images", model="physics", annotations=True, objects="2..3"),
    # A knob drawn per scenario: its draws are the batch's param_metal_noise.
    "drawn-metal-noise": dict(what="features", metal_noise="0..9"),
    # The thesis model's pixel noise drawn per scenario: images, features and param_pixel_noise.
    "drawn-pixel-noise": dict(what="both", pixel_noise="0..4"),
    # The physics camera and scene drawn per scenario: images, features, each param_<knob>
    # and the raw grid's mmw_raw_width and mmw_raw_height.
    "drawn-camera": dict(what="both", model="physics", netd="1..4", frames="1..8", illumination="285..305",
                         worn_minutes="0..60", ir_netd="0.03..0.1", mmw_raw="14x14,28x28,40x40"),
    # Random bodies drawn from their own seed: images, features and the subject column.
    "random-bodies": dict(what="both", model="physics", bodies="random", body_count=12, body_seed=8),
    # Drawn outfits with folds and seams drawn per scenario: param_clothing_folds.
    "clothing-folds": dict(what="both", model="physics", clothing="random", clothing_folds="0..1"),
    "spec-file": dict(spec="scenarios/case1-gun.toml", what="both", seed=5),
    # 20 regions, 33 zones, front and back MMW and IR views (tools/portal_catalogues.py).
    # The front MMW views' raw grid drawn; the back ones keep their own.
    "portal-20x33": dict(catalogue="tests/portals/portal-20x33.toml", what="images", annotations=True,
                         model="physics", objects="4..10", rule="gun", mmw_raw="12x12,28x28"),
}


def flags(keywords):
    out = []
    for k, v in keywords.items():
        flag = "--" + k.replace("_", "-")
        if k == "spec":
            v = str(v)
        if v is True and k in ("annotations", "balance"):
            out.append(flag)
        elif isinstance(v, bool):
            out += [flag, "on" if v else "off"]
        else:
            out += [flag, str(v)]
    return out


@pytest.mark.parametrize("case", sorted(CASES))
def test_batch_is_generate_rows(case, tmp_path, portalsim_bin, root, monkeypatch):
    monkeypatch.chdir(root)  # the spec file's relative path, as a user in the repository gives it
    kw = {"seed": 1, "count": N, **CASES[case]}
    out = tmp_path / "set"
    subprocess.run([portalsim_bin, "generate", *flags(kw), "--format", "h5", "--out", str(out), "--quiet"],
                   check=True)
    gen = portalsim.Generator(**kw)
    with h5py.File(out / "data.h5", "r") as f:
        assert list(f.attrs["datasets"]) == gen.datasets
        want = {k: f[k][:] for k in gen.datasets}
    # Batches of several sizes, and a range that starts inside a chunk.
    for start, count, step in ((0, N, N), (0, N, 7), (13, 50, 50), (N - 1, 1, 1)):
        got = {k: [] for k in gen.datasets}
        for s in range(start, start + count, step):
            b = gen.batch(s, min(step, start + count - s))
            assert sorted(b) == sorted(gen.datasets)
            for k, a in b.items():
                got[k].append(a)
        for k in gen.datasets:
            a = np.concatenate(got[k])
            w = want[k][start:start + count]
            assert a.dtype == w.dtype and a.shape == w.shape, f"{case} {k}: {a.dtype} {a.shape}, file {w.dtype} {w.shape}"
            assert a.tobytes() == w.tobytes(), f"{case} {k}: rows {start}..{start + count} (batches of {step}) differ"


def test_per_scenario_bodies_are_generate_rows_across_pages(tmp_path, portalsim_bin):
    """A body per scenario: batches inside a page, across its end, and back to page 0."""
    n = 200  # page 0 (0..191) and part of page 1
    kw = {"seed": 3, "count": n, "what": "both", "model": "physics", "bodies": "per-scenario", "body_seed": 4}
    out = tmp_path / "set"
    subprocess.run([portalsim_bin, "generate", *flags(kw), "--format", "h5", "--out", str(out), "--quiet"],
                   check=True)
    with h5py.File(out / "data.h5", "r") as f:
        want = {k: f[k][:] for k in f.attrs["datasets"]}
    assert not want["subject"].any()  # every row its own body
    gen = portalsim.Generator(**kw)
    assert sorted(gen.datasets) == sorted(want)
    for start, count, step in ((150, 50, 50), (0, n, n), (185, 15, 4), (190, 4, 4), (0, 192, 64)):
        got = {k: [] for k in gen.datasets}
        for s in range(start, start + count, step):
            for k, a in gen.batch(s, min(step, start + count - s)).items():
                got[k].append(a)
        for k in gen.datasets:
            a, w = np.concatenate(got[k]), want[k][start:start + count]
            assert a.dtype == w.dtype and a.shape == w.shape, f"{k}: {a.dtype} {a.shape}, file {w.dtype} {w.shape}"
            assert a.tobytes() == w.tobytes(), f"{k}: rows {start}..{start + count} (batches of {step}) differ"


def test_portal_counts_shape_the_batch(root):
    """A catalogue of 20 regions and 33 zones gives its batch keys its own shapes: a zone
    column each, a region column each, an image and a mask per camera view."""
    gen = portalsim.Generator(catalogue=str(root / "tests/portals/portal-20x33.toml"), what="both",
                              annotations=True, seed=3)
    b = gen.batch(0, 5)
    assert b["metal"].shape == (5, 33)
    assert b["region_object"].shape == (5, 20) and b["region_label"].shape == (5, 20)
    assert b["back_ir"].shape == (5, 200, 100, 3) and b["mask_back_ir"].shape == (5, 200, 100)
    assert b["features"].shape == (5, 4 * 20 * 20 + 20)


def test_arrays_own_the_buffers():
    """Zero copy: the arrays are views of C++ memory (not NumPy's own), each kept alive by a
    capsule, and they outlive the generator."""
    gen = portalsim.Generator(seed=2, what="images")
    b = gen.batch(0, 8)
    del gen
    for k, a in b.items():
        assert not a.flags.owndata, f"{k} was copied into NumPy's own memory"
        assert type(a.base).__name__ == "PyCapsule", f"{k}'s base is {type(a.base)}"
    again = portalsim.Generator(seed=2, what="images", prefetch=False).batch(0, 8)
    assert all(np.array_equal(b[k], again[k]) for k in b)


def test_prefetch_gives_the_same_rows():
    """The batch rendered ahead, and one asked for out of order, are the rows asked for."""
    ahead = portalsim.Generator(seed=3, what="images")
    plain = portalsim.Generator(seed=3, what="images", prefetch=False)
    for start, count in ((0, 16), (16, 16), (32, 16), (5, 9), (100, 16), (116, 16)):
        a, p = ahead.batch(start, count), plain.batch(start, count)
        for k in p:
            assert a[k].tobytes() == p[k].tobytes(), f"{k} of {start}..{start + count}"


def test_simulate_is_the_commands_output(tmp_path, portalsim_bin):
    """portalsim.simulate's arrays are what `portalsim simulate` writes: its images
    (upper.png, lower.png, ir.png) and its metal zones."""
    from PIL import Image

    one = portalsim.simulate(["none", "none", "none", "gun"], model="thesis", seed=4)
    out = tmp_path / "one"
    r = subprocess.run([portalsim_bin, "simulate", "none", "none", "none", "gun", "--model", "thesis", "--seed", "4",
                        "--out", str(out)], check=True, capture_output=True, text=True)
    zones = [int(z) for z in r.stdout.split("metal ")[1].split()[0].split(",")]
    assert one["metal"].tolist() == zones
    for view in ("upper", "lower", "ir"):
        png = np.asarray(Image.open(out / f"{view}.png"))
        assert png.shape == one[view].shape and np.array_equal(png, one[view]), f"{view} differs from {view}.png"
    assert int(one["label"]) == (1 if "threat yes" in r.stdout else 0)


@pytest.mark.parametrize("case", ["thesis", "physics-rotated", "thesis-annotations"])
def test_selected_datasets_are_the_same_bytes(case):
    """Generator(datasets=...) returns only those, in data.h5's order, each byte for byte as
    with every dataset made: narrowing what is computed (no IR view, no masks, no features,
    no metal zones) changes no other output."""
    kw = {"seed": 6, **CASES[case]}
    full = portalsim.Generator(prefetch=False, **kw)
    want = full.batch(3, 40)
    names = full.datasets
    picks = [["upper", "lower", "label"], ["ir"], ["ir_index", "subject"], ["metal", "region_label"],
             ["lower", "upper"]]
    picks += [[n] for n in names if n.startswith("mask_") or n == "features" or n.startswith("region_r")]
    for pick in picks:
        gen = portalsim.Generator(datasets=pick, **kw)
        assert gen.datasets == [n for n in names if n in pick]
        for start in (3, 23):  # the second batch was rendered ahead
            got = gen.batch(start, 20)
            assert list(got) == gen.datasets
            for k, a in got.items():
                assert a.tobytes() == want[k][start - 3:start + 17].tobytes(), f"{case} {pick}: {k} differs"
