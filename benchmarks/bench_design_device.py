"""Designs on CUDA against the CPU, and CUDA training's repeatability (issue 36).

Prints, on a machine where torch sees a GPU: the best validation loss of two 2-epoch
trainings of one seed on CUDA, with and without ``torch.use_deterministic_algorithms``;
then the wall time of K realisable targets designed with ``verify=False`` with
device="auto" (refinement on the CPU, bulk work and the BEM check on CUDA), on CUDA and on
one CPU thread (the second call of each), and of one design with its BEM check.
Start it with ``CUBLAS_WORKSPACE_CONFIG=:4096:8`` for the deterministic run.

    CUBLAS_WORKSPACE_CONFIG=:4096:8 python benchmarks/bench_design_device.py [--ks 1 30]
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
from pathlib import Path

import torch

import metainterface as mi
from metainterface.surrogate.config import TrainConfig

sys.path.insert(0, str(Path(__file__).parent))
from bench_design import realisable_targets

# Quick mode (`python benchmarks/run.py run --quick`, CI): seconds, same code paths.
QUICK = "--ks 1"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--ks", type=int, nargs="+", default=[1, 30])
    args = ap.parse_args()
    if not torch.cuda.is_available():
        print("unmeasured: torch sees no CUDA device")
        return
    tmp = Path(tempfile.mkdtemp())
    mi.generate_dataset(600, tmp / "d.npz", seed=1, progress=False, device="cpu")
    cfg = TrainConfig(epochs=2, batch_size=64, physics_steps=32)
    for det in (False, True):
        torch.use_deterministic_algorithms(det, warn_only=True)
        losses = [
            mi.train_surrogate(
                tmp / "d.npz", tmp / f"r{det}{i}", cfg, progress=False, device="cuda"
            ).best_val_loss
            for i in range(2)
        ]
        print(f"deterministic={det}: losses {losses}, rel {abs(losses[0] / losses[1] - 1):.1e}")
    torch.use_deterministic_algorithms(False)
    torch.set_num_threads(1)
    for k in args.ks:
        targets = realisable_targets(k, seed=11)
        for dev in ("auto", "cuda", "cpu"):
            mi.design(targets[:1], device=dev, verify=False)  # warm-up
            t0 = time.perf_counter()
            results = mi.design(targets, device=dev, verify=False)
            sec = time.perf_counter() - t0
            worst = max(r.error for r in results)
            print(f"K={k} {dev} verify=False: {sec:.2f} s, worst error {worst:.2e}", flush=True)
    one = realisable_targets(1, seed=11)
    for dev in ("auto", "cuda", "cpu"):
        t0 = time.perf_counter()
        mi.design(one, device=dev)
        print(f"K=1 {dev} with the BEM check: {time.perf_counter() - t0:.2f} s", flush=True)


if __name__ == "__main__":
    main()
