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
difference.

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

import metainterface as mi
from bench_offset_f0 import design_law
from metainterface.verify.adhesive import ORDER, accuracy, solve_adhesive

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
    print("| law (seed) | area | check's estimate | fine vs reference | held | seconds |")
    print("| --- | ---: | ---: | ---: | --- | ---: |")
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
            area = r.target.meta["friction"]["area_m2"]
            print(
                f"| {seed} | {area * 1e4:.3g} cm^2 | {100 * estimate:.2f} % | {100 * diff:.2f} % "
                f"| {'yes' if diff <= estimate else 'NO'} | {time.perf_counter() - start:.0f} |",
                flush=True,
            )
    print(
        f"\nthe estimate holds the fine grid's difference to the reference on {held} of "
        f"{len(args.seeds)} designs"
    )


if __name__ == "__main__":
    main()
