"""One design on one core: the paper's pipeline and the default design (issue 36).

Budgets (in-process, one core, import and the first call excluded): the paper's pipeline,
``mi.design(t, effort=mi.Effort(hedge=0, fallback=0), verify=False)``, <= 0.3 s per
built-in target; the default design, ``mi.design(t, verify=False)`` (hedges, fallback),
<= 2x that.

Prints per built-in target the median over --repeats of each, their ratio, and the errors;
then the errors of both on the --batch realisable random-cell targets of bench_design.py
(one batched call each; median, p90, max), the quality that a speed-up must keep.
--profile NAME prints cProfile's top rows (by cumulative time) of one design of that kind
("paper" or "default") on the bilinear target.

The machine may be shared: compare figures as ratios within one run, not across runs.
Run: python benchmarks/bench_design_speed.py [--repeats 5] [--batch 100] [--profile paper]
"""

import argparse
import cProfile
import pstats
import sys
import time
from pathlib import Path

import numpy as np
import torch

import metainterface as mi

sys.path.insert(0, str(Path(__file__).parent))
from bench_design import realisable_targets

torch.set_num_threads(1)  # one core, before any design runs

KINDS = {
    "paper": dict(effort=mi.Effort(hedge=0, fallback=0), verify=False),
    "default": dict(verify=False),
}


def timed(target: mi.Target, kind: str, repeats: int) -> tuple[float, float, float]:
    """Median wall and CPU seconds of ``repeats`` designs of ``target``, and the design's
    error. On a loaded machine the CPU time (of this process, one thread) drifts less."""
    wall, cpu, err = [], [], float("nan")
    for _ in range(repeats):
        t0, c0 = time.perf_counter(), time.process_time()
        r = mi.design(target, **KINDS[kind])
        wall.append(time.perf_counter() - t0)
        cpu.append(time.process_time() - c0)
        err = r.error
    return float(np.median(wall)), float(np.median(cpu)), err


def profile(kind: str, rows: int) -> None:
    t = mi.Target.builtin("bilinear")
    mi.design(t, **KINDS[kind])
    pr = cProfile.Profile()
    pr.enable()
    mi.design(t, **KINDS[kind])
    pr.disable()
    pstats.Stats(pr).sort_stats("cumtime").print_stats(rows)


# Quick mode (`python benchmarks/run.py run --quick`, CI): seconds, same code paths.
QUICK = "--repeats 1 --batch 1 --builtins saturating"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--batch", type=int, default=100)
    ap.add_argument("--builtins", nargs="+", metavar="NAME", help="default: all built-ins")
    ap.add_argument("--profile", choices=tuple(KINDS), default=None)
    ap.add_argument("--rows", type=int, default=30, help="profile rows printed")
    args = ap.parse_args()
    if args.profile:
        profile(args.profile, args.rows)
        return
    print(f"torch {torch.__version__}, {torch.get_num_threads()} thread(s)")
    mi.design("bilinear", **KINDS["default"])  # warm-up: imports, model load, caches
    print(f"median of {args.repeats}: wall s (CPU s of this process); ratio default / paper by CPU")
    print(
        f"{'target':<12}{'paper s':>16}{'default s':>16}{'ratio':>7}{'paper err':>11}"
        f"{'default err':>13}"
    )
    for name in args.builtins or mi.Target.builtins():
        t = mi.Target.builtin(name)
        tp, cp, ep = timed(t, "paper", args.repeats)
        td, cd, ed = timed(t, "default", args.repeats)
        print(
            f"{name:<12}{tp:>8.3f} ({cp:.3f}){td:>8.3f} ({cd:.3f}){cd / cp:>7.2f}"
            f"{100 * ep:>10.4f}%{100 * ed:>12.4f}%"
        )
    if args.batch:
        batch = realisable_targets(args.batch)
        for kind in KINDS:
            t0, c0 = time.perf_counter(), time.process_time()
            res = mi.design(batch, **KINDS[kind])
            wall, cpu = time.perf_counter() - t0, time.process_time() - c0
            e = 100 * np.array([r.error for r in res])
            print(
                f"{args.batch} realisable targets, {kind:<8}: error median {np.median(e):.4f} %,"
                f" p90 {np.percentile(e, 90):.4f} %, max {e.max():.4f} %, "
                f"fallback used {sum(r.fallback for r in res)}, "
                f"{wall:.1f} s ({cpu:.1f} s CPU) in one call"
            )


if __name__ == "__main__":
    main()
