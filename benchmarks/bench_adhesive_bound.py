"""The adhesive BEM check bounding its own error (issue 52): its cost and its two-grid
error estimate on a 9-asperity adhesive cell, idle and beside busy processes.

The cell: the held-back adhesive cell of ``metainterface._testing.adhesive_cell_curve``
(seed 11, 9 asperities, PDMS on glass: w = 50 mJ/m^2, E* = 2.4 MPa, R = 0.5 mm), checked
against its own loading curve (24 rows) with ``bem_check`` and ``Verify(correct=False)``
(the default grid and loads; ``--grid`` fixes one). Prints the grids solved, the check's
BEM error, its own error estimate (``accuracy``) and the wall time. ``--busy N`` runs N
``python3 -c "while True: pass"`` beside it.

``--restarts``: the check's fine path (``--grid``, default 384^2) continued and restarted at
each of its approaches in turn (``jkr_path(restart=k)``, as ``rising_branch`` runs it at
``RESTART_SHARE``): the largest difference in alpha at the restarted state and after it.

``--design``: the whole job a user runs instead, timed from the shell: ``metainterface
design`` of the same cell's loading curve as a friction law over 4 cm^2 (tau 0.3 MPa) with
the work of adhesion, at its defaults (the design, its adhesive BEM check and whatever the
check leads to), in a fresh process (imports included). Issue 52 asks <= 20 s.

    PYTHONPATH=src python benchmarks/bench_adhesive_bound.py [--grid 192] [--busy 2] [--design]
        [--restarts]
"""

from __future__ import annotations

import argparse
import functools
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

import metainterface as mi
from _held_back import W_J, E, R, write_law
from metainterface._testing import adhesive_cell_curve, held_back_cell
from metainterface._threads import uses_threads
from metainterface.validation.adhesive_path import APPROACHES_PER_LOAD, approaches, jkr_path
from metainterface.validation.heightmap import height_map
from metainterface.verify.check import bem_check

# Quick mode (`python benchmarks/run.py run --quick`, CI): seconds, same code paths.
QUICK = "--grid 384"  # the default grid: the disc criterion (a coarser one falls back)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--grid", type=int, default=None)
    ap.add_argument("--busy", type=int, default=0)
    ap.add_argument("--design", action="store_true", help="time `metainterface design` whole")
    ap.add_argument("--restarts", action="store_true", help="the path restarted at each state")
    args = ap.parse_args()
    if args.design:
        whole_design(args.busy)
        return
    w = W_J / (E * R)
    s = mi.CellSettings()
    g, h = held_back_cell(11, s)  # the cell of adhesive_cell_curve(seed=11)
    design = mi.Design(gamma=g, h=h, settings=s)
    p, a = adhesive_cell_curve(w, seed=11, rows=24)
    target = mi.Target(p_star=p, alpha=a, name="held-back")
    if args.restarts:
        restarts(design, target, mi.Independent(adhesion=w), args.grid or 384)
        return
    busy = [subprocess.Popen([sys.executable, "-c", "while True: pass"]) for _ in range(args.busy)]
    try:
        start = time.perf_counter()
        check = bem_check(
            design, target, mi.Verify(grid=args.grid, correct=False), mi.Independent(adhesion=w)
        )
        wall = time.perf_counter() - start
    finally:
        for proc in busy:
            proc.kill()
    print(
        f"busy {args.busy}: grid {check.grid}^2, {check.p_star.size} states, BEM error "
        f"{100 * check.bem_error:.3g} % (model {100 * check.model_error:.3g} %), its own error "
        f"+- {100 * check.accuracy:.2g} %, solves {check.seconds:.1f} s, wall {wall:.1f} s"
    )
    print("\n".join(check.notes))


@uses_threads()  # one torch thread a chain, as the check runs it
def restarts(design: mi.Design, target: mi.Target, model: mi.Independent, grid: int) -> None:
    """The check's path on ``grid``^2 continued and restarted at each approach: per restart
    k, the largest |d alpha| at state k and after it, over alpha there."""
    top = min(target.p_star_max, model.model_curve(design).p_star_max)
    deltas = approaches(design, model, top, APPROACHES_PER_LOAD * 10)
    hm = height_map(design, grid)
    work = model.adhesion * design.settings.e_star * design.settings.radius
    path = functools.partial(
        jkr_path, hm.heights, hm.cell_side, work, deltas, stop_above=top * (1 + 1e-9)
    )
    start = time.perf_counter()
    full = path()
    once = time.perf_counter() - start
    k_all = full.alpha.size
    print(f"grid {grid}^2: {k_all} states continued in {once:.1f} s; restarted at k:")
    print("| k | alpha at k | max abs(d alpha) at k / alpha | after k | wall (s) |")
    print("| ---: | ---: | ---: | ---: | ---: |")
    worst = 0.0
    for k in range(1, k_all):
        start = time.perf_counter()
        split = path(restart=k)
        wall = time.perf_counter() - start
        rel = np.abs(split.alpha - full.alpha[: split.alpha.size]) / full.alpha[: split.alpha.size]
        after = float(rel[k + 1 :].max(initial=0.0))
        worst = max(worst, float(rel[k]), after)
        print(f"| {k} | {full.alpha[k]:.4f} | {rel[k]:.2e} | {after:.2e} | {wall:.1f} |")
    print(f"largest relative difference in alpha: {worst:.2e}")


def whole_design(busy_count: int) -> None:
    """``metainterface design`` of the seed-11 cell's law, in a fresh process, timed."""
    with tempfile.TemporaryDirectory() as tmp:
        law = write_law(Path(tmp) / "law.csv", seed=11)
        argv = [
            sys.executable, "-m", "metainterface", "design", "--friction-csv", str(law),
            "--shear-strength", "0.3MPa", "--modulus", "2.4MPa", "--radius", "0.5mm",
            "--work-of-adhesion", "50mJ/m2", "--area", "4cm2", "--out", str(Path(tmp) / "out"),
        ]  # fmt: skip
        env = {k: v for k, v in os.environ.items() if not k.startswith(("OMP_", "MKL_"))}
        busy = [
            subprocess.Popen([sys.executable, "-c", "while True: pass"]) for _ in range(busy_count)
        ]
        try:
            start = time.perf_counter()
            run = subprocess.run(argv, capture_output=True, text=True, env=env)
            wall = time.perf_counter() - start
        finally:
            for proc in busy:
                proc.kill()
    line = next((x for x in run.stdout.splitlines() if x.startswith("law ")), "")
    print(f"busy {busy_count}: metainterface design, exit {run.returncode}, wall {wall:.1f} s")
    print(line or run.stderr.strip().splitlines()[-1])


if __name__ == "__main__":
    main()
