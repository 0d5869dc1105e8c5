"""A torch.utils.data.Dataset over the data.h5 that `portalsim generate --format h5` writes.

    from portalsim_dataset import PortalsimDataset
    ds = PortalsimDataset("out/data.h5", views=("upper", "lower"))
    x, y = ds[0]   # x: float32 tensor (2, 200, 200) in [0, 1]; y: int64 label (1 = threat)

`views` picks the image datasets stacked as channels (views of one size: upper and lower
are 200x200; ir is 200x100x3 and comes alone, channels first). `target` is "label" (one
class per scenario), "region_label" (13 per-region threat labels, float32) or "mask" (the
instance masks of the chosen views, int64 (V, H, W): each pixel the region 1-13 whose
object covers it, 0 none; needs a set made with --annotations). For detection, `boxes()`
gives an item's boxes from its masks. With randomised objects (--rotate, --scale, --flip),
`transforms(i)` gives item i's per-region rotation, scale and flip, as scenarios.csv
records them (`has_transforms` says whether the file has them). The file is
opened lazily in each worker process, so the dataset works with DataLoader(num_workers>0).
Needs Debian python3-torch, python3-h5py, python3-numpy.
"""
import h5py
import numpy as np
import torch
from torch.utils.data import Dataset


class PortalsimDataset(Dataset):
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

    # transforms() keys and the datasets they come from (each N x 13).
    TRANSFORMS = {"rotation": "region_rotation", "scale": "region_scale", "flip": "region_flip"}

    def transforms(self, i):
        """Item i's randomised-object transforms, one value per region (13): "rotation"
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
