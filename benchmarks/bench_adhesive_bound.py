"""The adhesive BEM check bounding its own error (issue 52): its cost and its two-grid
error estimate on a 9-asperity adhesive cell, idle and beside busy processes.

The cell: the held-back adhesive cell of ``metainterface._testing.adhesive_cell_curve``
(seed 11, 9 asperities, PDMS on glass: w = 50 mJ/m^2, E* = 2.4 MPa, R = 0.5 mm), checked
against its own loading curve (24 rows) with ``bem_check`` and ``Verify(correct=False)``
(the default grid and loads; ``--grid`` fixes one). Prints the grids solved, the check's
BEM error, its own error estimate (``accuracy``) and the wall time. ``--busy N`` runs N
``python3 -c "while True: pass"`` beside it.

    PYTHONPATH=src python benchmarks/bench_adhesive_bound.py [--grid 192] [--busy 2]
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import time

import numpy as np

import metainterface as mi
from metainterface._testing import adhesive_cell_curve
from metainterface.verify.check import bem_check

E, R, W_J = 2.4e6, 0.5e-3, 0.05
# Quick mode (`python benchmarks/run.py run --quick`, CI): seconds, same code paths.
QUICK = "--grid 96"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--grid", type=int, default=None)
    ap.add_argument("--busy", type=int, default=0)
    args = ap.parse_args()
    w = W_J / (E * R)
    s = mi.CellSettings()
    rng = np.random.default_rng(11)  # the cell of adhesive_cell_curve(seed=11)
    g = rng.uniform(1.8, 4.0, 9)
    h = rng.uniform(0, 0.6, 9) * s.delta_max
    design = mi.Design(gamma=g, h=h - h.min(), settings=s)
    p, a = adhesive_cell_curve(w, seed=11, rows=24)
    target = mi.Target(p_star=p, alpha=a, name="held-back")
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


if __name__ == "__main__":
    main()
