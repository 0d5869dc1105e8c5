#!/usr/bin/python3
"""portalsim transfer's CNN: trains tools/train_example.py's small CNN on one data.h5's MMW
views and scores it on others.

  /usr/bin/python3 transfer_cnn.py OUT.json TRAIN.h5 TEST.h5 [TEST.h5 ...] [--steps 300] [--seed 0]

Each data.h5 needs the datasets `upper`, `lower` (uint8 N x H x W, the two MMW views, as
`generate --what both --format h5` writes them) and `label`. The CNN sees the two views as
channels, each image standardised (zero mean, unit variance), averaged down 4 times, and trains with Adam (learning rate 2e-3), batch 32, for
--steps steps on batches drawn from the training set in a fixed order (torch's --seed).
Writes {"correct": [...], "n": [...]} for the test files in order. Needs Debian's
python3-torch, python3-h5py and python3-numpy.
"""
import argparse
import json
import sys

import h5py
import numpy as np
import torch
from torch import nn


def model(channels):
    """The small CNN (tools/train_example.py imports it from here)."""
    return nn.Sequential(
        nn.AvgPool2d(4),
        nn.Conv2d(channels, 16, 5, padding=2), nn.ReLU(), nn.MaxPool2d(2),
        nn.Conv2d(16, 32, 3, padding=1), nn.ReLU(), nn.MaxPool2d(2),
        nn.Conv2d(32, 32, 3, padding=1), nn.ReLU(), nn.AdaptiveMaxPool2d(1),
        nn.Flatten(), nn.Linear(32, 2))


def load(path):
    """(views uint8 N x 2 x H x W, labels int64 N)."""
    with h5py.File(path, "r") as f:
        for key in ("upper", "lower", "label"):
            if key not in f:
                sys.exit(f"{path}: no dataset '{key}': the CNN reads the MMW views upper and lower and the label "
                         "(a set made with images: --what both --format h5)")
        if f["upper"].shape != f["lower"].shape:
            sys.exit(f"{path}: upper and lower differ in shape")
        x = np.stack([f["upper"][:], f["lower"][:]], axis=1)
        y = f["label"][:].astype(np.int64)
    return torch.from_numpy(x), torch.from_numpy(y)


def standard(x):
    """Each image of a uint8 batch N x 2 x H x W to zero mean and unit variance: the camera's
    window and the room's brightness move every pixel of a view together."""
    x = x.float()
    mean = x.mean(dim=(2, 3), keepdim=True)
    sd = x.std(dim=(2, 3), keepdim=True).clamp_min(1.0)
    return (x - mean) / sd


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("out")
    p.add_argument("train")
    p.add_argument("tests", nargs="+")
    p.add_argument("--steps", type=int, default=300)
    p.add_argument("--seed", type=int, default=0)
    a = p.parse_args()
    torch.manual_seed(a.seed)
    torch.set_num_threads(2)
    x, y = load(a.train)
    if len(set(y.tolist())) < 2:
        sys.exit(f"{a.train}: the training set has a single class")
    net = model(2)
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
        loss = loss_fn(net(standard(x[idx])), y[idx])
        loss.backward()
        opt.step()
        if (step + 1) % 100 == 0:
            print(f"transfer: CNN step {step + 1}: loss {loss.item():.3f}", file=sys.stderr, flush=True)
    net.eval()
    correct, n = [], []
    with torch.no_grad():
        for path in a.tests:
            tx, ty = load(path)
            right = 0
            for at in range(0, len(ty), 256):
                right += (net(standard(tx[at:at + 256])).argmax(1) == ty[at:at + 256]).sum().item()
            correct.append(right)
            n.append(len(ty))
    with open(a.out, "w") as f:
        json.dump({"correct": correct, "n": n}, f)


if __name__ == "__main__":
    main()
