"""BEM validation wall time (the default engine, torch): the load path of one design.

Targets (issue 6), on the 2-core machine:
  768 x 768, 20 loads, one 9-asperity design (the packaged example): <= 60 s wall
  256 x 256, 8 loads: <= 3 s wall (a 2 x 2 design: 256 is not a multiple of 3)
Wall time depends on what else runs on the cores: the load average is printed with it.
Run: python benchmarks/bench_validate.py [--jobs 2] [--only small|large] [--scaling]
"""

import argparse
import os
import time
from importlib.resources import files

import numpy as np

from metainterface.physics import Design
from metainterface.runtime import tune_allocator
from metainterface.validation import available_cpus, plan_validation

SMALL = Design(gamma=np.array([1.8, 2.6, 3.3, 4.0]), h=np.array([0.0, 0.003, 0.006, 0.01]))


def run(name: str, design: Design, grid: int, loads: int, jobs: int, target: float) -> None:
    load_before = os.getloadavg()[0]
    t0 = time.perf_counter()
    cpu0 = os.times()
    plan = plan_validation(design, grid, loads)
    res = plan.solve(jobs)
    wall = time.perf_counter() - t0
    cpu1 = os.times()
    cpu = (cpu1.user - cpu0.user) + (cpu1.children_user - cpu0.children_user)
    per = res.seconds
    print(
        f"{name}: {grid} x {grid}, {loads} loads, N = {design.n_asperities}, jobs = {jobs}: "
        f"wall {wall:.1f} s (target <= {target:g} s); "
        f"solver {per.sum():.1f} s summed over loads ({per.min():.2f}-{per.max():.2f} s each); "
        f"CPU (self + finished workers) {cpu:.1f} s; load average before {load_before:.1f}"
    )
    print(
        f"  max |alpha_bem / alpha_model - 1|: {100 * res.max_rel_err_upper:.2f} % "
        f"(upper half), {100 * res.max_rel_err:.2f} % (all); max p/E* = {res.p_max.max():.3f}"
    )


def scaling(jobs: int) -> None:
    """Seconds per solve against grid size (example design, 4 loads), and jobs at 768."""
    example = Design.load(files("metainterface") / "examples" / "example_design.json")
    for grid, j in ((192, 1), (384, 1), (768, 1), (768, jobs)):
        t0 = time.perf_counter()
        res = plan_validation(example, grid, 4).solve(j)
        print(
            f"  scaling: M = {grid:4d}, jobs = {j}: {np.mean(res.seconds):.2f} s per solve, "
            f"{time.perf_counter() - t0:.1f} s wall for 4 loads "
            f"(load average {os.getloadavg()[0]:.1f})"
        )


# Quick mode (`python benchmarks/run.py run --quick`, CI): seconds, same code paths.
QUICK = "--only small"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--jobs", type=int, default=min(2, available_cpus()))
    ap.add_argument("--only", choices=("small", "large"))
    ap.add_argument("--scaling", action="store_true", help="also time one solve vs grid size")
    args = ap.parse_args()
    tune_allocator()  # as the CLI does
    if args.only != "large":
        run("small", SMALL, 256, 8, args.jobs, 3)
    if args.only != "small":
        example = Design.load(files("metainterface") / "examples" / "example_design.json")
        run("paper", example, 768, 20, args.jobs, 60)
    if args.scaling:
        scaling(args.jobs)


if __name__ == "__main__":
    main()
