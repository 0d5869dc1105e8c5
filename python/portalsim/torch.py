"""PyTorch datasets of portalsim scenarios (Debian python3-torch, python3-h5py, python3-numpy).

StreamDataset: scenarios straight from the kernels, no file written.

    from torch.utils.data import DataLoader
    from portalsim.torch import StreamDataset
    ds = StreamDataset(spec="scenarios/case1-gun.toml", seed=1, views=("upper", "lower"), target="label",
                       start=0, count=None, rotate="-30..30")   # count=None: endless
    for x, y in DataLoader(ds, batch_size=32, num_workers=2): ...

Sample i is generate's row i (the same for any number of DataLoader workers or
torch.distributed ranks): the index range start..start+count is dealt out in blocks of
`batch` scenarios, block j to shard j mod (ranks x workers). Make the dataset after
torch.distributed.init_process_group, or launch with torchrun (RANK, WORLD_SIZE): DataLoader
workers do not see the process group. Each worker makes its own
OpenCL context when it starts iterating (after the fork: a context made before a fork hangs
PoCL), with POCL_MAX_PTHREAD_COUNT set so that workers x threads fit the cores.

H5Dataset: a torch.utils.data.Dataset over the data.h5 that `portalsim generate --format h5`
writes.

    ds = H5Dataset("out/data.h5", views=("upper", "lower"))
    x, y = ds[0]   # x: float32 tensor (2, 200, 200) in [0, 1]; y: int64 label (1 = threat)

In both, `views` picks the image datasets stacked as channels (views of one size: upper and
lower are 200x200; ir is 200x100x3 and comes alone, channels first). `target` is "label" (one
class per scenario), "region_label" (a threat label per region of the catalogue, 13 in the
built-in one, float32) or "mask" (the instance masks of the chosen views, int64 (V, H, W):
each pixel the region 1..R whose object covers it, 0 none; an H5Dataset needs a set made with --annotations). For detection,
`H5Dataset.boxes()` gives an item's boxes from its masks. With randomised objects (--rotate,
--scale, --flip), `H5Dataset.transforms(i)` gives item i's per-region rotation, scale and flip,
as scenarios.csv records them (`has_transforms` says whether the file has them). The file is
opened lazily in each worker process, so the dataset works with DataLoader(num_workers>0).
"""
import os

import h5py
import numpy as np
import torch
from torch.utils.data import Dataset, IterableDataset, get_worker_info

import portalsim

class H5Dataset(Dataset):
    """A torch.utils.data.Dataset over a data.h5 (see the module's docstring)."""

    def __init__(self, path, views=("upper", "lower"), target="label", indices=None, in_memory=False):
        self.path = str(path)
        self.views = tuple(views)
        self.target = target
        # The datasets a target reads.
        self._targets = tuple(f"mask_{v}" for v in self.views) if target == "mask" else (target,)
        with h5py.File(self.path, "r") as f:
            missing = [v for v in (*self.views, *self._targets) if v not in f]
            if missing:
                raise KeyError(f"{self.path}: no dataset {', '.join(missing)} "
                               f"(it has {', '.join(sorted(f.keys()))}; images need --what images|both)")
            self.length = f[self._targets[0]].shape[0]
            self.has_transforms = all(k in f for k in self.TRANSFORMS.values())
            self.class_names = [str(c) for c in f.attrs["class_names"]]
            self.spec = f.attrs["spec"]
            shapes = {f[v].shape[1:3] for v in self.views}
            if len(shapes) != 1:
                raise ValueError(f"{self.path}: views {self.views} differ in size {sorted(shapes)}")
        self.indices = np.arange(self.length) if indices is None else np.asarray(indices)
        self._file = None
        # in_memory: read the chosen scenarios once (fast epochs; needs N x pixels bytes).
        self._cache = None
        if in_memory:
            with h5py.File(self.path, "r") as f:
                self._cache = {k: f[k][:][self.indices] for k in (*self.views, *self._targets)}

    # transforms() keys and the datasets they come from (each N x the regions).
    TRANSFORMS = {"rotation": "region_rotation", "scale": "region_scale", "flip": "region_flip"}

    def transforms(self, i):
        """Item i's randomised-object transforms, one value per region: "rotation"
        (float64 degrees, counter-clockwise in the image), "scale" (float64 factor), "flip"
        (uint8, 1 = mirrored left to right), and "object" (int16, -1 where the region is
        empty, which has rotation 0, scale 1, flip 0)."""
        if not self.has_transforms:
            raise KeyError(f"{self.path}: no transforms (the set was made without --rotate, --scale or --flip)")
        f, j = self._h5(), int(self.indices[i])
        out = {k: f[name][j] for k, name in self.TRANSFORMS.items()}
        out["object"] = f["region_object"][j]
        return out

    def __len__(self):
        return len(self.indices)

    def _h5(self):
        if self._file is None:
            self._file = h5py.File(self.path, "r")
        return self._file

    def __getitem__(self, i):
        if self._cache is not None:
            f, j = self._cache, i
        else:
            f, j = self._h5(), int(self.indices[i])
        planes = []
        for v in self.views:
            a = f[v][j]
            planes.extend(np.moveaxis(a, -1, 0) if a.ndim == 3 else a[None])
        x = torch.from_numpy(np.stack(planes).astype(np.float32) / 255.0)
        if self.target == "mask":
            return x, torch.from_numpy(np.stack([f[m][j] for m in self._targets]).astype(np.int64))
        y = f[self.target][j]
        y = torch.tensor(y, dtype=torch.float32) if self.target == "region_label" else torch.tensor(int(y))
        return x, y

    @staticmethod
    def boxes(mask):
        """The boxes of one view's mask (H, W): {region: (x, y, w, h)} over the pixels each
        region's object owns, as annotations.json's bbox."""
        m = np.asarray(mask)
        out = {}
        for r in np.unique(m):
            if r == 0:
                continue
            ys, xs = np.nonzero(m == r)
            out[int(r)] = (int(xs.min()), int(ys.min()), int(xs.max() - xs.min() + 1), int(ys.max() - ys.min() + 1))
        return out

    def __getstate__(self):  # DataLoader workers open their own handle
        s = dict(self.__dict__)
        s["_file"] = None
        return s


def _channels(arrays, views):
    """The views of a batch (N, H, W) or (N, H, W, 3) as channels (N, C, H, W); no copy for
    one gray view."""
    planes = [arrays[v][:, None] if arrays[v].ndim == 3 else np.moveaxis(arrays[v], -1, 1) for v in views]
    return planes[0] if len(planes) == 1 else np.concatenate(planes, axis=1)


def _ranks(made_at=(0, 1)):
    """(rank, ranks) of torch.distributed: its process group where this process sees one
    initialised; in a DataLoader worker (which does not) the RANK and WORLD_SIZE that torchrun
    and other launchers set, or else `made_at`, the group the dataset was made in."""
    if torch.distributed.is_available() and torch.distributed.is_initialized():
        return torch.distributed.get_rank(), torch.distributed.get_world_size()
    if os.environ.get("RANK", "").isdigit() and os.environ.get("WORLD_SIZE", "").isdigit():
        return int(os.environ["RANK"]), int(os.environ["WORLD_SIZE"])
    return made_at


def _shard(made_at):
    """(this process's shard, shards, workers): torch.distributed's rank x DataLoader's worker."""
    info = get_worker_info()
    worker, workers = (info.id, info.num_workers) if info is not None else (0, 1)
    rank, ranks = _ranks(made_at)
    return rank * workers + worker, ranks * workers, workers


def _threads_per_worker(workers):
    """Threads for each of `workers` processes so that together they fit this process's
    cores; PoCL's (POCL_MAX_PTHREAD_COUNT, read when the worker's OpenCL context is made)
    are set to it, or kept where already lower."""
    cores = len(os.sched_getaffinity(0))
    per = max(1, cores // max(1, workers))
    given = os.environ.get("POCL_MAX_PTHREAD_COUNT", "")
    if given.isdigit() and 0 < int(given) < per:
        per = int(given)
    os.environ["POCL_MAX_PTHREAD_COUNT"] = str(per)
    return per


class StreamDataset(IterableDataset):
    """generate's scenarios start..start+count (count=None: endless) as (x, y) samples.

    Keywords are portalsim.Generator's (generate's flags: rule, balance, objects, model, any
    knob); `what` defaults to "images". `batch` scenarios are rendered per call; with
    `batched=True` the dataset yields whole blocks (x (B, C, H, W), y (B, ...)), for
    DataLoader(batch_size=None). `scale=False` gives x as uint8 (no conversion, no copy for
    one view) instead of float32 in [0, 1]. `indices=True` yields (i, x, y), i the scenario
    index (a tensor of them when batched).
    """

    def __init__(self, spec=None, seed=0, views=("upper", "lower"), target="label", start=0, count=None,
                 batch=256, batched=False, scale=True, indices=False, **keywords):
        if target not in ("label", "region_label", "mask"):
            raise ValueError(f"target: {target!r} is not label, region_label or mask")
        if start < 0 or (count is not None and count < 0) or batch < 1:
            raise ValueError(f"start {start}, count {count}, batch {batch}: expected start >= 0, count >= 0, batch >= 1")
        self.views, self.target = tuple(views), target
        self.start, self.count, self.batch, self.batched, self.scale = int(start), count, int(batch), batched, scale
        self.indices = indices
        self.ranks = _ranks()  # a worker, forked later, no longer sees the process group
        keywords.setdefault("what", "images" if self.views else "features")
        if target == "mask":
            keywords["annotations"] = True
        self.keywords = dict(keywords, spec=None if spec is None else str(spec), seed=seed)
        # The keywords are checked now (ValueError here, not in a worker); this generator
        # makes no OpenCL context and no thread, so nothing of it crosses a fork.
        names = set(portalsim.Generator(prefetch=False, **self.keywords).datasets)
        wanted = list(self.views) + ([f"mask_{v}" for v in self.views] if target == "mask" else [target])
        missing = [v for v in wanted if v not in names]
        if missing:
            raise ValueError(f"views/target: no dataset {', '.join(missing)} (these keywords make {', '.join(sorted(names))})")
        self._datasets = list(dict.fromkeys(wanted))  # only these are rendered

    def __len__(self):
        if self.count is None:
            raise TypeError("StreamDataset(count=None) is endless and has no length")
        return self.count if not self.batched else -(-self.count // self.batch)

    def blocks(self, shard, shards):
        """The (start, count) blocks shard `shard` of `shards` renders, in order."""
        j = shard
        while True:
            lo = self.start + j * self.batch
            if self.count is not None and lo >= self.start + self.count:
                return
            hi = lo + self.batch if self.count is None else min(lo + self.batch, self.start + self.count)
            yield lo, hi - lo
            j += shards

    def _sample(self, b):
        x = _channels(b, self.views)
        # As H5Dataset's, bit for bit: NumPy's float32 division (torch divides by a scalar
        # as a product with its reciprocal).
        x = torch.from_numpy(np.true_divide(x, np.float32(255), dtype=np.float32) if self.scale else x)
        if self.target == "mask":
            y = torch.from_numpy(np.stack([b[f"mask_{v}"] for v in self.views], axis=1).astype(np.int64))
        elif self.target == "region_label":
            y = torch.from_numpy(b["region_label"].astype(np.float32))
        else:
            y = torch.from_numpy(b["label"].astype(np.int64))
        return x, y

    def __iter__(self):
        shard, shards, workers = _shard(self.ranks)
        keywords = dict(self.keywords)
        if get_worker_info() is not None:
            keywords.setdefault("threads", _threads_per_worker(workers))
        gen = portalsim.Generator(datasets=self._datasets, **keywords)
        blocks = self.blocks(shard, shards)
        todo = next(blocks, None)
        while todo is not None:
            after = next(blocks, None)
            b = gen.batch(*todo, next_start=after[0] if after else None)
            x, y = self._sample(b)
            if self.batched:
                yield (torch.arange(todo[0], todo[0] + todo[1]), x, y) if self.indices else (x, y)
            else:
                for i in range(len(y)):
                    yield (todo[0] + i, x[i], y[i]) if self.indices else (x[i], y[i])
            todo = after
