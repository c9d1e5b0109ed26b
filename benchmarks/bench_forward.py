"""Exact alpha(P*) curves for 100,000 designs x 9 asperities x 128 steps.

Target (issue 2): <= 2 s wall and <= 1.5 GB peak memory on the 2-core CI machine.
Run: python benchmarks/bench_forward.py [--designs 100000] [--repeat 3]
"""

import argparse
import resource
import time

import numpy as np
import torch

from metainterface.physics import CellSettings, curves_numpy
from metainterface.runtime import tune_allocator

# Quick mode (`python benchmarks/run.py run --quick`, CI): seconds, same code paths.
QUICK = "--designs 1000 --repeat 1"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--designs", type=int, default=100_000)
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args()
    tune_allocator()  # as the CLI does
    s = CellSettings()
    rng = np.random.default_rng(0)
    gamma = rng.uniform(s.gamma_min, s.gamma_max, (args.designs, s.n_asperities))
    h = rng.uniform(0, s.delta_max, (args.designs, s.n_asperities))
    curves_numpy(gamma[:2048], h[:2048], s)  # warm-up
    times = []
    for _ in range(args.repeat):
        t0 = time.perf_counter()
        out = curves_numpy(gamma, h, s)
        times.append(time.perf_counter() - t0)
    assert np.isfinite(out["alpha_hat"]).all() and np.isfinite(out["stiffness_hat"]).all()
    peak_mb = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    print(
        f"forward exact curves: {args.designs} designs x {s.n_asperities} asperities x "
        f"{s.n_steps} steps, float32, torch {torch.__version__}, {torch.get_num_threads()} threads"
    )
    print(f"  wall: best {min(times):.2f} s, median {np.median(times):.2f} s (target <= 2 s)")
    print(f"  peak memory (process RSS): {peak_mb:.0f} MB (target <= 1500 MB)")


if __name__ == "__main__":
    main()
