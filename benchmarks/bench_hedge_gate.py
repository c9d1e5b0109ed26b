"""The hedge gate (``Effort.hedge_error``) against design quality and cost: 100 realisable
targets (exact curves of random cells, ``bench_design.realisable_targets``) designed in one
batched call per setting, ``verify=False``, one thread, and the README's ``saturating`` and
``bilinear`` targets. Prints CPU seconds of this process and the error's median, p90 and
largest per setting (the numbers in ``results/design_speed.md``, 2026-11-27).

The gate was chosen on the targets of seed 0 (``--seed``); the same figures on the targets of
``--held-out-seed`` (1), on which nothing was chosen, are printed beside them.

    PYTHONPATH=src python benchmarks/bench_hedge_gate.py [--gates 1e-4 5e-4 1e-3] [--seed 0]
        [--held-out-seed 1]
"""

from __future__ import annotations

import argparse
import sys
import time
import warnings
from pathlib import Path

import numpy as np
import torch

import metainterface as mi

sys.path.insert(0, str(Path(__file__).parent))
from bench_design import realisable_targets

# Quick mode (`python benchmarks/run.py run --quick`, CI): seconds, same code paths.
QUICK = "--gates 1e-3 --targets 1"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--gates", type=float, nargs="+", default=[1e-4, 5e-4, 1e-3])
    ap.add_argument("--seed", type=int, default=0, help="the targets the gate was chosen on")
    ap.add_argument("--held-out-seed", type=int, default=1, help="targets nothing was chosen on")
    ap.add_argument("--targets", type=int, default=100)
    args = ap.parse_args()
    warnings.simplefilter("ignore")
    torch.set_num_threads(1)
    sets = {
        f"chosen on (seed {args.seed})": realisable_targets(args.targets, seed=args.seed),
        f"held out (seed {args.held_out_seed})": realisable_targets(
            args.targets, seed=args.held_out_seed
        ),
    }
    mi.design("bilinear", verify=False)  # warm-up: the networks, the envelope
    for gate in args.gates:
        effort = mi.Effort(hedge_error=gate)
        for label, targets in sets.items():
            t0 = time.process_time()
            res = mi.design(targets, verify=False, effort=effort)
            cpu = time.process_time() - t0
            err = 100 * np.array([r.error for r in res])
            print(
                f"hedge_error {gate:g}, {label}: {args.targets} targets {cpu:.1f} CPU s, median "
                f"{np.median(err):.4f} % p90 {np.percentile(err, 90):.4f} % max "
                f"{err.max():.4f} %, within 0.1 %: {int((err <= 0.1).sum())}",
                flush=True,
            )
        built = []
        for name in ("saturating", "bilinear"):
            t1 = time.process_time()
            r = mi.design(name, verify=False, effort=effort)
            built.append(f"{name} {time.process_time() - t1:.2f} s {100 * r.error:.4f} %")
        print(f"hedge_error {gate:g}, built-ins: " + "; ".join(built), flush=True)


if __name__ == "__main__":
    main()
