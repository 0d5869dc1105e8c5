"""StreamDataset: scenario i's sample is Generator row i (generate's row i, test_generator.py)
for any number of DataLoader workers and torch.distributed ranks; endless and resumable.

The tests that fork DataLoader workers come first and render nothing in this process (the
expected rows are made in a spawned one): PoCL hangs in a child forked from a process that
had made an OpenCL context, which the last test checks is an error instead."""
import itertools
import os

import numpy as np
import pytest
import torch
import torch.distributed as dist
import torch.multiprocessing as mp
from torch.utils.data import DataLoader

import portalsim
from portalsim.torch import StreamDataset

KW = dict(seed=7, rule="gun", objects="0..3", views=("upper", "lower"), target="region_label")
N = 45


def _rows(start, count):
    b = portalsim.Generator(seed=7, rule="gun", objects="0..3", what="images").batch(start, count)
    x = np.stack([b["upper"], b["lower"]], axis=1).astype(np.float32) / 255
    return {start + i: (x[i], b["region_label"][i].astype(np.float32)) for i in range(count)}


def expected(start, count):
    """Generator rows start..start+count as the stream's samples, made in a spawned process."""
    with mp.get_context("spawn").Pool(1) as pool:
        return pool.apply(_rows, (start, count))


def collect(ds, **loader):
    got = {}
    for i, x, y in DataLoader(ds, batch_size=None, **loader):
        i = int(i)
        assert i not in got, f"scenario {i} came twice"
        got[i] = (x.numpy(), y.numpy())
    return got


def check(got, want):
    assert sorted(got) == sorted(want)
    for i in want:
        assert np.array_equal(got[i][0], want[i][0]) and np.array_equal(got[i][1], want[i][1]), f"scenario {i}"


@pytest.mark.parametrize("workers", [1, 2, 3])
def test_any_number_of_workers(workers):
    ds = StreamDataset(start=5, count=N, batch=8, indices=True, **KW)
    check(collect(ds, num_workers=workers), expected(5, N))


def _rank(rank, ranks, init, out):
    dist.init_process_group("gloo", init_method=init, rank=rank, world_size=ranks)
    ds = StreamDataset(start=5, count=N, batch=4, indices=True, **KW)
    got = collect(ds, num_workers=2)
    torch.save(got, f"{out}.{rank}")
    dist.destroy_process_group()


@pytest.mark.parametrize("ranks", [3])
def test_any_number_of_ranks(ranks, tmp_path):
    """torch.distributed ranks (gloo, one process each) with 2 workers each: together every
    scenario once, each as row i. Three ranks make six shards that split the range unevenly;
    test_blocks_cover_the_range_once checks the split itself for 1, 2, 5 and 16 shards (two
    ranks, 9 more PyTorch processes, found nothing that three do not)."""
    mp.spawn(_rank, args=(ranks, f"file://{tmp_path}/pg", str(tmp_path / "got")), nprocs=ranks, join=True)
    got = {}
    for r in range(ranks):
        part = torch.load(tmp_path / f"got.{r}")
        assert part, f"rank {r} of {ranks} streamed nothing"
        assert not set(part) & set(got), f"rank {r} repeats scenarios"
        got.update(part)
    check(got, expected(5, N))


def test_blocks_cover_the_range_once():
    ds = StreamDataset(start=3, count=100, batch=7, **KW)
    for shards in (1, 2, 5, 16):
        seen = sorted(i for s in range(shards) for lo, n in ds.blocks(s, shards) for i in range(lo, lo + n))
        assert seen == list(range(3, 103)), f"{shards} shards"


def test_workers_limit_pocl_threads(monkeypatch):
    """Each worker's PoCL threads times the workers fit the cores."""
    monkeypatch.delenv("POCL_MAX_PTHREAD_COUNT", raising=False)
    ds = StreamDataset(count=2, batch=1, indices=True, **KW)

    class Probe(torch.utils.data.IterableDataset):
        def __iter__(self):
            for _ in ds:
                pass
            yield int(os.environ["POCL_MAX_PTHREAD_COUNT"])

    cores = len(os.sched_getaffinity(0))
    for workers in (1, 2):
        got = list(DataLoader(Probe(), batch_size=None, num_workers=workers))
        assert got and all(g * workers <= max(cores, workers) for g in got), f"{workers} workers: {got}"


def test_in_this_process():
    """No workers: the DataLoader iterates here (this process makes its OpenCL context now)."""
    ds = StreamDataset(start=5, count=N, batch=8, indices=True, **KW)
    check(collect(ds, num_workers=0), expected(5, N))


def test_endless_and_resumed():
    """count=None goes on past any spec count; a stream resumed from index k gives k, k+1..."""
    endless = StreamDataset(count=None, batch=16, indices=True, **KW)
    head = list(itertools.islice(iter(endless), 40))
    assert [int(i) for i, _, _ in head] == list(range(40))
    resumed = StreamDataset(start=1030, count=None, batch=16, indices=True, **KW)
    later = dict((int(i), (x.numpy(), y.numpy())) for i, x, y in itertools.islice(iter(resumed), 20))
    check(later, expected(1030, 20))


def test_fork_after_a_context_is_an_error_not_a_hang():
    """This process has an OpenCL context by now: a forked worker says so and stops."""
    portalsim.Generator(seed=1).batch(0, 1)
    ds = StreamDataset(count=4, batch=2, **KW)
    with pytest.raises(RuntimeError, match="multiprocessing_context"):
        list(DataLoader(ds, batch_size=None, num_workers=1))
    spawned = list(DataLoader(ds, batch_size=None, num_workers=1, multiprocessing_context="spawn"))
    assert len(spawned) == 4
