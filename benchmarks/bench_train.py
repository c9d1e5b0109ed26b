"""Benchmark: seconds per training epoch of the surrogate over 80,000 training samples.

    python benchmarks/bench_train.py [--dataset FILE | --samples 100000] [--epochs 4]
        [--batch-size 512]

Target (issue 4) on the 2-core dev machine: <= 3 s an epoch, validation and the atomic
checkpoint included (what metrics.csv records), for the recipe of the shipped model. Without
--dataset, 100,000 samples of the default settings are generated first (seed 0, ~3 s), the
size the shipped model was trained on (80 % of it is the training split). The first epoch
warms the allocator and caches up and is reported apart. The process's minor page faults per
epoch are printed too: glibc returning freed tensors to the kernel shows up there
(see :mod:`metainterface.runtime`).
"""

from __future__ import annotations

import argparse
import resource
import statistics
import tempfile
import time
from pathlib import Path

import torch

from metainterface.data import generate_dataset, load_dataset
from metainterface.physics import CellSettings
from metainterface.runtime import tune_allocator
from metainterface.surrogate.config import TrainConfig
from metainterface.surrogate.data import split_of
from metainterface.surrogate.run_state import read_metrics
from metainterface.surrogate.train import train


def _minor_faults() -> int:
    return resource.getrusage(resource.RUSAGE_SELF).ru_minflt


# Quick mode (`python benchmarks/run.py run --quick`, CI): seconds, same code paths.
QUICK = "--samples 2000 --epochs 2"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--dataset", help="dataset .npz (default: generate 100,000 samples)")
    parser.add_argument("--samples", type=int, default=100_000, help="without --dataset")
    parser.add_argument("--epochs", type=int, default=4)
    parser.add_argument("--batch-size", type=int, default=512)
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        path = args.dataset
        if path is None:
            path = Path(tmp) / "data.npz"
            generate_dataset(args.samples, 0, CellSettings(), path, progress=False)
        ds = load_dataset(path)
        train_split, val_split = split_of(ds, "train"), split_of(ds, "val")
        config = TrainConfig(
            epochs=args.epochs, batch_size=args.batch_size, curriculum_epochs=15, seed=0
        )
        tuned = tune_allocator()
        faults, t0 = _minor_faults(), time.perf_counter()
        train(train_split, val_split, ds.settings, Path(tmp) / "run", config, progress=False)
        wall, faults = time.perf_counter() - t0, _minor_faults() - faults
        seconds = read_metrics(Path(tmp) / "run")["seconds"]
    steady = seconds[1:] if len(seconds) > 1 else seconds
    print(
        f"surrogate training: {len(train_split)} training / {len(val_split)} validation samples, "
        f"batch {args.batch_size}, torch {torch.__version__}, {torch.get_num_threads()} threads, "
        f"allocator tuned: {tuned}"
    )
    print(f"  first epoch: {seconds[0]:.2f} s (warm-up)")
    print(
        f"  epochs 2-{len(seconds)}: median {statistics.median(steady):.2f} s, "
        f"best {min(steady):.2f} s, worst {max(steady):.2f} s (target <= 3 s)"
    )
    print(f"  minor page faults: {faults / len(seconds):,.0f} an epoch; wall {wall:.1f} s")


if __name__ == "__main__":
    main()
