#!/usr/bin/env python3
"""Trains a small CNN on a portalsim data.h5 for a few hundred steps and prints accuracy.

    portalsim generate --count 2000 --seed 1 --rule gun --balance --what images \\
        --format h5 --out gunset
    python3 tools/train_example.py gunset/data.h5 --steps 300

Holds out the last 20% of scenarios, trains on the rest (Adam, batch 32, the two MMW
views as channels averaged down to 50x50), and prints "accuracy A on N held-out
scenarios (chance C)". Exits 1 if the accuracy is not above chance by --min-margin.
"""
import argparse
import pathlib
import sys

import torch
from torch import nn
from torch.utils.data import DataLoader

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
from portalsim_dataset import PortalsimDataset  # noqa: E402


def model(channels):
    return nn.Sequential(
        nn.AvgPool2d(4),
        nn.Conv2d(channels, 16, 5, padding=2), nn.ReLU(), nn.MaxPool2d(2),
        nn.Conv2d(16, 32, 3, padding=1), nn.ReLU(), nn.MaxPool2d(2),
        nn.Conv2d(32, 32, 3, padding=1), nn.ReLU(), nn.AdaptiveMaxPool2d(1),
        nn.Flatten(), nn.Linear(32, 2))


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("h5")
    p.add_argument("--steps", type=int, default=300)
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--min-margin", type=float, default=0.1, help="fail unless accuracy > chance + this")
    a = p.parse_args()
    torch.manual_seed(a.seed)
    torch.set_num_threads(2)
    full = PortalsimDataset(a.h5, views=("upper", "lower"))
    n = len(full)
    cut = n * 4 // 5
    train = PortalsimDataset(a.h5, views=full.views, indices=range(cut), in_memory=True)
    test = PortalsimDataset(a.h5, views=full.views, indices=range(cut, n), in_memory=True)
    net = model(2)
    opt = torch.optim.Adam(net.parameters(), lr=2e-3)
    loss_fn = nn.CrossEntropyLoss()
    step = 0
    net.train()
    while step < a.steps:
        for x, y in DataLoader(train, batch_size=32, shuffle=True):
            opt.zero_grad()
            loss = loss_fn(net(x), y)
            loss.backward()
            opt.step()
            step += 1
            if step % 50 == 0:
                print(f"step {step}: loss {loss.item():.3f}", flush=True)
            if step >= a.steps:
                break
    net.eval()
    correct, labels = 0, []
    with torch.no_grad():
        for x, y in DataLoader(test, batch_size=128):
            correct += (net(x).argmax(1) == y).sum().item()
            labels.extend(y.tolist())
    acc = correct / len(test)
    majority = max(labels.count(0), labels.count(1)) / len(labels)
    print(f"accuracy {acc:.3f} on {len(test)} held-out scenarios (chance {majority:.3f})")
    return 0 if acc > majority + a.min_margin else 1


if __name__ == "__main__":
    sys.exit(main())
