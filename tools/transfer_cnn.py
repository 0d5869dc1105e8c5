#!/usr/bin/python3
"""portalsim transfer's CNN: trains a small CNN on one data.h5's sensors and scores it on others.

  /usr/bin/python3 transfer_cnn.py OUT.json TRAIN.h5 TEST.h5 [TEST.h5 ...]
      [--inputs mmw,ir,metal] [--mmw-views upper,lower] [--ir-views ir_index] [--steps 300] [--seed 0]

--inputs names the sensors the network sees, as a portal's operator fuses them:
  mmw    the catalogue's MMW views, datasets named by --mmw-views (uint8 N x H x W), a
         channel each: `upper` and `lower` for the built-in portal, four with a back camera;
  ir     the IR views' palette indices, datasets named by --ir-views (uint8 N x H x W);
  metal  the metal detector's zones, dataset `metal` (uint8 N x Z).
portalsim transfer passes --mmw-views and --ir-views from the catalogue's [[views]].
Each image is standardised (zero mean, unit variance: a camera's window and its room move
every pixel of a view together), averaged down 4 times and read by its own convolutional
branch (tools/train_example.py's small CNN without its last layer, 32 features); the zones
are standardised per zone with the training set's mean and SD and read by one dense layer
(32 features); one linear layer decides from the branches' features side by side. With
--inputs mmw alone the network is tools/train_example.py's (a channel per MMW view). Trains with Adam
(learning rate 2e-3), batch 32, for --steps steps on batches drawn from the training set in
a fixed order (torch's --seed). Writes {"correct": [...], "n": [...]} for the test files in
order. Needs Debian's python3-torch, python3-h5py and python3-numpy.
"""
import argparse
import json
import sys

import h5py
import numpy as np
import torch
from torch import nn

SENSORS = ("mmw", "ir", "metal")
# Each sensor's datasets, the built-in catalogue's until main() sets the catalogue's.
DATASETS = {"mmw": ("upper", "lower"), "ir": ("ir_index",), "metal": ("metal",)}


def trunk(channels):
    """The convolutional layers of the small CNN: an image batch to 32 features."""
    return [nn.AvgPool2d(4),
            nn.Conv2d(channels, 16, 5, padding=2), nn.ReLU(), nn.MaxPool2d(2),
            nn.Conv2d(16, 32, 3, padding=1), nn.ReLU(), nn.MaxPool2d(2),
            nn.Conv2d(32, 32, 3, padding=1), nn.ReLU(), nn.AdaptiveMaxPool2d(1),
            nn.Flatten()]


def model(channels):
    """The small CNN (tools/train_example.py imports it from here)."""
    return nn.Sequential(*trunk(channels), nn.Linear(32, 2))


class Fused(nn.Module):
    """One branch per sensor, their features side by side, one linear decision."""

    def __init__(self, inputs, zones):
        super().__init__()
        self.inputs = inputs
        self.branches = nn.ModuleDict()
        for s in inputs:
            if s == "metal":
                self.branches[s] = nn.Sequential(nn.Linear(zones, 32), nn.ReLU())
            else:  # an image sensor, a channel per dataset
                self.branches[s] = nn.Sequential(*trunk(len(DATASETS[s])))
        self.decide = nn.Linear(32 * len(inputs), 2)

    def forward(self, x):
        return self.decide(torch.cat([self.branches[s](x[s]) for s in self.inputs], dim=1))


def load(path, inputs):
    """({sensor: uint8 tensor}, labels int64 N): images N x C x H x W, zones N x Z."""
    with h5py.File(path, "r") as f:
        need = [k for s in inputs for k in DATASETS[s]] + ["label"]
        for key in need:
            if key not in f:
                sys.exit(f"{path}: no dataset '{key}': the CNN's inputs ({','.join(inputs)}) need "
                         f"{', '.join(need)} (a set made with images: --what both --format h5)")
        n = f["label"].shape[0]
        x = {}
        for s in inputs:
            keys = DATASETS[s]
            if s == "metal":
                x[s] = f["metal"][:]
            else:  # an image sensor: its datasets as channels
                if len({f[k].shape for k in keys}) != 1:
                    sys.exit(f"{path}: {' and '.join(keys)} differ in shape")
                x[s] = np.stack([f[k][:] for k in keys], axis=1)
            if x[s].shape[0] != n:
                sys.exit(f"{path}: {DATASETS[s][0]} has {x[s].shape[0]} rows, label {n}")
        y = f["label"][:].astype(np.int64)
    return {s: torch.from_numpy(v) for s, v in x.items()}, torch.from_numpy(y)


def standard(x):
    """Each image of a uint8 batch N x C x H x W to zero mean and unit variance."""
    x = x.float()
    mean = x.mean(dim=(2, 3), keepdim=True)
    sd = x.std(dim=(2, 3), keepdim=True).clamp_min(1.0)
    return (x - mean) / sd


class Prepare:
    """A batch of raw sensor tensors to the network's input; zones by the training set's statistics."""

    def __init__(self, train_x, inputs):
        self.inputs = inputs
        if "metal" in inputs:
            z = train_x["metal"].float()
            self.zone_mean = z.mean(dim=0, keepdim=True)
            self.zone_sd = z.std(dim=0, keepdim=True).clamp_min(1.0)

    def __call__(self, x, idx):
        if self.inputs == ["mmw"]:
            return standard(x["mmw"][idx])
        out = {}
        for s in self.inputs:
            v = x[s][idx]
            out[s] = (v.float() - self.zone_mean) / self.zone_sd if s == "metal" else standard(v)
        return out


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("out")
    p.add_argument("train")
    p.add_argument("tests", nargs="+")
    p.add_argument("--inputs", default="mmw", help="comma-separated sensors: mmw, ir, metal")
    p.add_argument("--mmw-views", default=",".join(DATASETS["mmw"]), help="the MMW views' datasets")
    p.add_argument("--ir-views", default=",".join(DATASETS["ir"]), help="the IR views' palette index datasets")
    p.add_argument("--steps", type=int, default=300)
    p.add_argument("--seed", type=int, default=0)
    a = p.parse_args()
    inputs = a.inputs.split(",")
    if not inputs or any(s not in SENSORS for s in inputs) or len(set(inputs)) != len(inputs):
        p.error(f"--inputs: '{a.inputs}' is not a list of distinct sensors among {', '.join(SENSORS)}")
    for s, names in (("mmw", a.mmw_views), ("ir", a.ir_views)):
        DATASETS[s] = tuple(n for n in names.split(",") if n)
        if s in inputs and not DATASETS[s]:
            p.error(f"--inputs: {s}, but --{s}-views names no dataset")
    print(f"transfer: the CNN reads {', '.join(k for s in inputs for k in DATASETS[s])}", file=sys.stderr, flush=True)
    torch.manual_seed(a.seed)
    torch.set_num_threads(2)
    x, y = load(a.train, inputs)
    if len(set(y.tolist())) < 2:
        sys.exit(f"{a.train}: the training set has a single class")
    net = model(len(DATASETS["mmw"])) if inputs == ["mmw"] else Fused(inputs, x["metal"].shape[1] if "metal" in x else 0)
    prepare = Prepare(x, inputs)
    opt = torch.optim.Adam(net.parameters(), lr=2e-3)
    loss_fn = nn.CrossEntropyLoss()
    net.train()
    order = torch.randperm(len(y))
    for step in range(a.steps):
        at = (step * 32) % len(y)
        if at + 32 > len(y):
            order = torch.randperm(len(y))
            at = 0
        idx = order[at:at + 32]
        opt.zero_grad()
        loss = loss_fn(net(prepare(x, idx)), y[idx])
        loss.backward()
        opt.step()
        if (step + 1) % 100 == 0:
            print(f"transfer: CNN step {step + 1}: loss {loss.item():.3f}", file=sys.stderr, flush=True)
    net.eval()
    correct, n = [], []
    with torch.no_grad():
        for path in a.tests:
            tx, ty = load(path, inputs)
            if "metal" in inputs and tx["metal"].shape[1] != x["metal"].shape[1]:
                sys.exit(f"{path}: metal has {tx['metal'].shape[1]} zones, the training set "
                         f"{x['metal'].shape[1]}")
            right = 0
            for at in range(0, len(ty), 256):
                idx = torch.arange(at, min(at + 256, len(ty)))
                right += (net(prepare(tx, idx)).argmax(1) == ty[idx]).sum().item()
            correct.append(right)
            n.append(len(ty))
    with open(a.out, "w") as f:
        json.dump({"correct": correct, "n": n}, f)


if __name__ == "__main__":
    main()
