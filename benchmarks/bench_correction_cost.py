"""What the BEM check and its correction cost on realisable targets (issue 36): ``mi.design``
with its default check of N realisable targets (``bench_design.realisable_targets(N,
seed=11)``), one after another; prints the CPU seconds of this process and its BEM workers
and each target's BEM error. Compare two source trees by running it on each in turn
(``PYTHONPATH=<tree>/src``), alternately.

    PYTHONPATH=src python benchmarks/bench_correction_cost.py [--targets 5] [--grid 384]
        [--iterations 3]

``--grid``: the check's grid (default: the check's own, 384^2 for N = 9); ``--iterations``:
the correction's most BEM solves (default: the check's own, 3).
"""

from __future__ import annotations

import argparse
import os
import sys
import time
import warnings
from pathlib import Path

import metainterface as mi

sys.path.insert(0, str(Path(__file__).parent))
from bench_design import realisable_targets


def cpu() -> float:
    """CPU seconds of this process and its finished children (the BEM's workers)."""
    t = os.times()
    return t.user + t.system + t.children_user + t.children_system


# Quick mode (`python benchmarks/run.py run --quick`, CI): seconds, same code paths.
QUICK = "--targets 1 --grid 96 --iterations 1"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--targets", type=int, default=5)
    ap.add_argument("--grid", type=int, default=None, help="the check's grid")
    ap.add_argument("--iterations", type=int, default=3, help="the correction's most solves")
    args = ap.parse_args()
    warnings.simplefilter("ignore")
    verify = mi.Verify(grid=args.grid, iterations=args.iterations)
    mi.design("saturating", verify=verify)  # warm-up: the networks, the envelope, the workers
    targets = realisable_targets(args.targets, seed=11)
    c0, w0 = cpu(), time.perf_counter()
    errors = [f"{100 * mi.design(t, verify=verify).bem.bem_error:.2f}" for t in targets]
    print(
        f"{mi.__file__}: CPU {cpu() - c0:.1f} s, wall {time.perf_counter() - w0:.1f} s; "
        f"BEM errors %: {' '.join(errors)}"
    )


if __name__ == "__main__":
    main()
