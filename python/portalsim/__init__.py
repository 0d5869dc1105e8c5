"""portalsim for Python: the simulator's scenarios as NumPy arrays, straight from its kernels.

    import portalsim
    gen = portalsim.Generator(spec="scenarios/case1-gun.toml", seed=1, what="images",
                              model="physics", rotate="-30..30", annotations=True)
    b = gen.batch(start=0, count=1024)   # dict of NumPy arrays, as data.h5's datasets
    one = portalsim.simulate(["none", "none", "none", "gun"], model="thesis")

Every keyword is a flag of `portalsim generate` (or `simulate`) with "_" for "-": spec, seed,
count, rule, pool, objects, subjects, balance, what, annotations, tier and every model knob
(`portalsim knobs`). `gen.batch(start, count)` is byte for byte rows start..start+count of the
data.h5 that `portalsim generate --format h5` writes with the same keywords. A bad keyword or
value raises ValueError with the command line's message. portalsim.torch holds the PyTorch
datasets (H5Dataset over a data.h5, StreamDataset straight from the kernels).

Supported interpreter: Debian's /usr/bin/python3 (tools/install-python.sh installs the package
for it). docs/guide/python.md is the guide.
"""
try:
    from . import _core
except ImportError as _error:
    import pathlib as _pathlib
    import sys as _sys
    import sysconfig as _sysconfig

    _built = sorted(p.name for p in _pathlib.Path(__file__).parent.glob("_core*.so"))
    _wanted = "_core" + (_sysconfig.get_config_var("EXT_SUFFIX") or ".so")
    if _built and _wanted not in _built:
        # pybind11 has no stable ABI: the module serves the one CPython it was built for.
        raise ImportError(
            f"portalsim's module {', '.join(_built)} was built for another Python than this one "
            f"({_sys.executable}, {_sys.version.split()[0]}, which loads {_wanted}); run it with "
            "that Python, or build portalsim for this one (docs/guide/python.md)"
        ) from _error
    raise

__version__ = _core.version
__all__ = ["Generator", "simulate", "__version__"]

# generate's flags that make no sense in memory: the output folder and its files (their
# formats and compression: Generator writes none), and how a run is split or shown.
# batch(start, count) takes the place of --batch and --shard.
_FILES_ONLY = {"out", "format", "compress", "image-format", "png-level", "stages"}
_NOT_IN_PYTHON = _FILES_ONLY | {"resume", "quiet", "shard", "batch", "timing"}
# Keywords whose list values are comma-separated names; other lists and tuples are ranges.
_LISTS = {"pool", "subjects"}


def _text(key, value):
    """A keyword's value as the command line's text."""
    if isinstance(value, bool):
        return "on" if value else "off"
    if isinstance(value, (list, tuple)):
        if key in _LISTS:
            return ",".join(str(v) for v in value)
        if len(value) != 2:
            raise ValueError(f"{key}: expected a range (low, high), got {value!r}")
        return f"{value[0]}..{value[1]}"
    return str(value)


def _flags(command, keywords):
    """generate's (or simulate's) flags for `keywords`, with the command line's names."""
    known = _core.flags(command)  # flag name (no "--") -> takes no value
    args = []
    for key, value in keywords.items():
        if value is None:
            continue
        flag = key.replace("_", "-")
        if flag not in known or flag in _NOT_IN_PYTHON:
            usable = sorted(k.replace("-", "_") for k in known if k not in _NOT_IN_PYTHON)
            name = "Generator" if command == "generate" else command
            why = (f"--{flag} only shapes the files `portalsim {command}` writes, and portalsim.{name} writes none"
                   if flag in _FILES_ONLY and flag in known else
                   f"`portalsim {command}` has no --{flag} here" if flag in known else
                   f"`portalsim {command}` has no --{flag}")
            raise ValueError(f"{key}: not a keyword of portalsim.{name} ({why}); the keywords are {', '.join(usable)}")
        if known[flag]:  # a switch such as --balance or --annotations
            if not isinstance(value, bool):
                raise ValueError(f"--{flag}: expected True or False, got {value!r}")
            args.append(f"--{flag}={'true' if value else 'false'}")
        else:
            args.append(f"--{flag}={_text(key, value)}")
    return args


class Generator:
    """generate's scenarios of a spec and seed, a batch at a time, as NumPy arrays.

    Keywords are generate's flags (spec, seed, count, what, rule, annotations, any knob...).
    `datasets` names the data.h5 datasets batch() returns (default: all of them, see
    `datasets`); only what they need is computed, so ("upper", "lower", "label") renders
    neither the IR view nor its palette. Each is byte for byte the same as with all made.
    The OpenCL context is made at the first batch, in the process that renders. With
    prefetch (the default), the batch after the one returned renders on a C++ thread while
    Python reads this one.
    """

    def __init__(self, spec=None, seed=None, *, prefetch=True, datasets=None, **keywords):
        self._keywords = dict(keywords, spec=None if spec is None else str(spec), seed=seed)
        if isinstance(datasets, str):
            datasets = [datasets]
        self._core = _core.Generator(["--out=(python)"] + _flags("generate", self._keywords), prefetch,
                                     None if datasets is None else [str(d) for d in datasets])

    def batch(self, start=0, count=1024, next_start=...):
        """Scenarios start .. start+count: a dict of NumPy arrays keyed and shaped as data.h5's
        datasets (upper, lower, ir, ir_index, mask_*, features, metal, label, subject,
        region_*), each owning its C++ buffer (no copy). With prefetch, the batch of `count`
        from `next_start` (default start+count; None: none) renders meanwhile."""
        start, count = int(start), int(count)
        if next_start is ...:
            next_start = start + count
        return self._core.batch(start, count, None if next_start is None else int(next_start))

    @property
    def datasets(self):
        """The keys of batch()'s dict, in data.h5's order."""
        return list(self._core.datasets)

    @property
    def count(self):
        """The spec's scenario count (a listed file's length); batch() may go past it for a
        generator spec, whose scenario i is a function of (seed, i) alone."""
        return self._core.count

    @property
    def seed(self):
        return self._core.seed

    def times(self):
        """Where the batches' time went so far, in seconds: {"scenarios", "scenes" (drawing
        them), "kernels" (the backend), "rows" (making data.h5's rows: the IR palette...)}."""
        return dict(self._core.times())


def simulate(objects, **keywords):
    """One scenario, as `portalsim simulate OBJECTS...` makes it: objects for the catalogue's
    regions in order (1..13 in the built-in one; "none" for an empty region, "gun:v" a
    drawing), and simulate's flags as keywords (subject, rule, threat, seed, tier, model,
    catalogue and every knob). Returns a dict of NumPy arrays without the scenario axis: one
    per camera view (upper, lower gray; ir RGB, ir_index), features, metal (the catalogue's
    zones, 19 in the built-in one), label, subject and region_*."""
    if isinstance(objects, str):
        objects = objects.split()
    return _core.simulate([str(o) for o in objects] + _flags("simulate", keywords))
