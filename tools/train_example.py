#!/usr/bin/env python3
"""Trains a small CNN on portalsim scenarios for a few hundred steps and prints accuracy.

From a data.h5:
    portalsim generate --count 2000 --seed 1 --rule gun --balance --what images \\
        --format h5 --out gunset
    python3 tools/train_example.py gunset/data.h5 --steps 300

From the stream, with no file written (portalsim.torch.StreamDataset: the same scenarios as
that generate run, rendered as the loop asks for them):
    python3 tools/train_example.py --stream --seed 1 --steps 300

The data.h5 way holds out the last 20% of scenarios and trains on the rest; the stream way
trains on scenarios 0, 1, 2, ... (an endless stream: each step sees new ones) and tests on
--test scenarios from index 10^9 on, which training never reaches. Both train with Adam,
batch 32, the two MMW views as channels averaged down to 50x50, and print "accuracy A on N
held-out scenarios (chance C)". Exits 1 if the accuracy is not above chance by --min-margin.
Needs the portalsim package (tools/install-python.sh) and Debian's python3-torch.
"""
import argparse
import sys

import torch
from torch import nn
from torch.utils.data import DataLoader

from portalsim.torch import H5Dataset, StreamDataset
from transfer_cnn import model  # the one network; portalsim transfer trains it with --cnn-inputs mmw

# The stream's scenarios: a balanced gun set, as the data.h5 example's generate command.
STREAM = dict(rule="gun", balance=True, what="images", views=("upper", "lower"))
TEST_START = 10**9


def loaders(a):
    """(training batches, held-out batches)."""
    if a.stream:
        train = StreamDataset(seed=a.seed, start=0, count=None, **STREAM)
        test = StreamDataset(seed=a.seed, start=TEST_START, count=a.test, **STREAM)
        return (DataLoader(train, batch_size=32, num_workers=a.workers),
                DataLoader(test, batch_size=128, num_workers=a.workers))
    full = H5Dataset(a.h5, views=("upper", "lower"))
    n = len(full)
    cut = n * 4 // 5
    train = H5Dataset(a.h5, views=full.views, indices=range(cut), in_memory=True)
    test = H5Dataset(a.h5, views=full.views, indices=range(cut, n), in_memory=True)
    return DataLoader(train, batch_size=32, shuffle=True), DataLoader(test, batch_size=128)


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("h5", nargs="?", help="a data.h5 (or --stream)")
    p.add_argument("--stream", action="store_true", help="train from portalsim.torch.StreamDataset, no file")
    p.add_argument("--steps", type=int, default=300)
    p.add_argument("--seed", type=int, default=0, help="torch's seed; with --stream also the scenarios' seed")
    p.add_argument("--test", type=int, default=500, help="--stream: held-out scenarios")
    p.add_argument("--workers", type=int, default=0, help="--stream: DataLoader workers")
    p.add_argument("--min-margin", type=float, default=0.1, help="fail unless accuracy > chance + this")
    a = p.parse_args()
    if a.stream == bool(a.h5):
        p.error("give a data.h5 or --stream")
    torch.manual_seed(a.seed)
    torch.set_num_threads(2)
    train, test = loaders(a)
    net = model(2)
    opt = torch.optim.Adam(net.parameters(), lr=2e-3)
    loss_fn = nn.CrossEntropyLoss()
    step = 0
    net.train()
    while step < a.steps:
        for x, y in train:
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
        for x, y in test:
            correct += (net(x).argmax(1) == y).sum().item()
            labels.extend(y.tolist())
    acc = correct / len(labels)
    majority = max(labels.count(0), labels.count(1)) / len(labels)
    print(f"accuracy {acc:.3f} on {len(labels)} held-out scenarios (chance {majority:.3f})")
    return 0 if acc > majority + a.min_margin else 1


if __name__ == "__main__":
    sys.exit(main())
