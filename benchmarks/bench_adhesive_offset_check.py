"""The issue-38 offset friction law, designed with its work of adhesion and checked in the
adhesive BEM at two grids: the design's error, and per BEM state alpha_bem / alpha_model - 1.

The law: a held-back adhesive cell's loading curve (``metainterface._testing``, seed 11,
24 rows) as a friction law in newtons for PDMS on glass (w = 50 mJ/m^2, E* = 2.4 MPa,
R = 0.5 mm), tau = 0.3 MPa over 4 cm^2. Designed by the default path (``verify=False``),
then ``bem_check`` with ``Verify(grid=G, loads=12, correct=False)``.

    PYTHONPATH=src python benchmarks/bench_adhesive_offset_check.py [--grids 96 192] [--zero-shot]
"""

from __future__ import annotations

import argparse
import tempfile
import time
import warnings
from pathlib import Path

import numpy as np

import metainterface as mi
from _held_back import AREA, TAU, E, R, write_law
from metainterface.verify.check import bem_check

# Quick mode (`python benchmarks/run.py run --quick`, CI): seconds, same code paths.
QUICK = "--grids 48 --zero-shot"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--grids", type=int, nargs="+", default=[96, 192])
    ap.add_argument("--zero-shot", action="store_true", help="the design before refinement")
    args = ap.parse_args()
    path = write_law(Path(tempfile.mkdtemp()) / "pdms.csv", seed=11)
    scale = dict(shear_strength=TAU, modulus=E, radius=R, area=AREA, fit="never")
    target = mi.Target.from_friction(path, work_of_adhesion="50mJ/m2", **scale)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        t0 = time.perf_counter()
        quick = dict(refine=False, hedge=0, fallback=0) if args.zero_shot else {}
        res = mi.design(target, verify=False, effort=mi.Effort(seed=0, **quick))
    print(
        f"design: error {100 * res.error:.2f} % ({time.perf_counter() - t0:.0f} s), "
        f"zero-shot from {res.zero_shot_from}",
        flush=True,
    )
    for grid in args.grids:
        t0 = time.perf_counter()
        chk = bem_check(
            res.design, res.target, mi.Verify(grid=grid, loads=12, correct=False), res.model
        )
        ratio = chk.alpha_bem / chk.alpha_model - 1
        l2 = np.linalg.norm(chk.alpha_bem - chk.alpha_model) / np.linalg.norm(chk.alpha_model)
        print(
            f"{grid}^2: {chk.p_star.size} states, BEM against the target "
            f"{100 * chk.bem_error:.2f} %, against the model {100 * l2:.2f} %, "
            f"per state {np.round(100 * ratio, 1)} % "
            f"({time.perf_counter() - t0:.0f} s)",
            flush=True,
        )


if __name__ == "__main__":
    main()
