"""Does the adhesive BEM check's two-grid accuracy bound its own error? (issue 52, item 3)

Each law is a held-back adhesive cell's loading curve (``adhesive_cell_curve``, 24 rows) as
a friction law over 4 cm^2 (tau 0.3 MPa, E* 2.4 MPa, R 0.5 mm, w 50 mJ/m^2, as
``bench_offset_f0.design_law``), designed by the default path without the check
(``--area-auto``: the area designed with the cell). The design's check is then solved as
``design`` solves it, on its two grids (``--grids``: coarse, fine; by default 192^2 and
384^2 at 10 loads), and on a reference grid twice the fine one with four times the approaches
(``verify.adhesive.solve_adhesive``). Per law: the check's own accuracy estimate
(``verify.adhesive.accuracy``, fine against coarse), the fine grid's difference to the
reference (the same measure: the reference's curve read at the fine grid's states, never
across one of its snap-ins, over the target's norm) and whether the estimate holds that
difference; and the same difference for the curve extrapolated from the two grids
(Richardson at order 1, 2 fine - coarse, at the fine grid's states): whether extrapolating
would make the check more accurate.

    PYTHONPATH=src python benchmarks/bench_adhesive_check_bound.py [--seeds 11 31 32]
        [--area-auto] [--grids 192 384 768] [--loads 10]

The reference has a discretisation error of its own, so a difference below the estimate is
necessary for a bound, not sufficient.
"""

from __future__ import annotations

import argparse
import tempfile
import time
from pathlib import Path

import numpy as np

import metainterface as mi
from bench_offset_f0 import design_law
from metainterface.verify.adhesive import ORDER, accuracy, read_across_jumps, solve_adhesive

# Quick mode (`python benchmarks/run.py run --quick`, CI): seconds, same code paths.
QUICK = "--seeds 31 --grids 48 96 192 --loads 3 --zero-shot"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, nargs="+", default=[11, 31, 32])
    ap.add_argument("--area-auto", action="store_true", help="design the area too")
    ap.add_argument("--grids", type=int, nargs=3, default=[192, 384, 768])
    ap.add_argument("--loads", type=int, default=10, help="the check's loads (default 10)")
    ap.add_argument("--zero-shot", action="store_true", help="the design before refinement")
    args = ap.parse_args()
    quick = {"refine": False, "hedge": 0, "fallback": 0} if args.zero_shot else {}
    effort = mi.Effort(seed=0, **quick)
    coarse_m, fine_m, ref_m = args.grids
    print(
        f"grids {coarse_m}^2 (coarse), {fine_m}^2 (fine), {ref_m}^2 (reference, "
        f"{4 * args.loads} loads); the check's loads: {args.loads}"
    )
    print(
        "| law (seed) | area | check's estimate | fine vs reference | held "
        "| extrapolated vs reference (fine, same states) | seconds |"
    )
    print("| --- | ---: | ---: | ---: | --- | ---: | ---: |")
    held = 0
    with tempfile.TemporaryDirectory() as tmp:
        for seed in args.seeds:
            start = time.perf_counter()
            r = design_law(Path(tmp), seed, args.area_auto, effort)
            solved = {
                m: solve_adhesive(r.design, r.target, r.model, grid=m, loads=k)
                for m, k in ((coarse_m, args.loads), (fine_m, args.loads), (ref_m, 4 * args.loads))
            }
            estimate = accuracy(solved[fine_m], solved[coarse_m], r.target)
            # accuracy() divides by 2^ORDER - 1: the plain difference to the reference
            diff = accuracy(solved[fine_m], solved[ref_m], r.target) * (2.0**ORDER - 1.0)
            held += diff <= estimate
            extra = extrapolated(solved[fine_m], solved[coarse_m], solved[ref_m], r.target)
            area = r.target.meta["friction"]["area_m2"]
            print(
                f"| {seed} | {area * 1e4:.3g} cm^2 | {100 * estimate:.2f} % | {100 * diff:.2f} % "
                f"| {'yes' if diff <= estimate else 'NO'} | {100 * extra[0]:.2f} % "
                f"({100 * extra[1]:.2f} %) "
                f"| {time.perf_counter() - start:.0f} |",
                flush=True,
            )
    print(
        f"\nthe estimate holds the fine grid's difference to the reference on {held} of "
        f"{len(args.seeds)} designs"
    )


def extrapolated(fine, coarse, ref, target) -> tuple[float, float]:
    """The order-1 Richardson curve 2 fine - coarse at the fine states (the coarse curve read
    there as ``accuracy`` reads it) against the reference, over the target's norm, at the
    states both read; and the fine curve's difference there."""
    c = read_across_jumps(fine.p_star, coarse.p_star, coarse.alpha_bem, coarse.snap_ins)
    f = read_across_jumps(fine.p_star, ref.p_star, ref.alpha_bem, ref.snap_ins)
    ok = np.isfinite(c) & np.isfinite(f)
    t = np.interp(fine.p_star[ok], target.p_star, target.alpha)
    norm = np.linalg.norm(t)
    a = fine.alpha_bem[ok]
    return float(np.linalg.norm(2 * a - c[ok] - f[ok]) / norm), float(
        np.linalg.norm(a - f[ok]) / norm
    )


if __name__ == "__main__":
    main()
