"""An offset friction law's F_0 (issue 38): held-back PDMS laws designed with the work of
adhesion, their curve error and their friction at zero load against the law's.

Each law is a held-back adhesive cell's loading curve (``adhesive_cell_curve``, 24 rows
from zero load) as a friction law over 4 cm^2 (tau 0.3 MPa, E* 2.4 MPa, R 0.5 mm, w 50
mJ/m^2), designed by the default path without the BEM check. The curve error weighs the
zero-load row as one point of many; the design's note states F_0 against the law's.

    PYTHONPATH=src python benchmarks/bench_offset_f0.py [--seeds 11 12 13] [--range 11 30]
        [--zero-shot]

Ends with the median and largest curve error and |F_0 error| over the laws (``--range A B``:
the seeds A..B). ``--zero-shot``: the design before its refinement, as
``bench_friction_laws.py`` measures it (``Effort(refine=False, hedge=0, fallback=0)``).
"""

from __future__ import annotations

import argparse
import re
import statistics
import tempfile
import time
import warnings
from pathlib import Path

import metainterface as mi
from metainterface._testing import adhesive_cell_curve

E, R, W_J, TAU, AREA = 2.4e6, 0.5e-3, 0.05, 0.3e6, 4e-4


# Quick mode (`python benchmarks/run.py run --quick`, CI): seconds, same code paths.
QUICK = "--seeds 11"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, nargs="+", default=[11, 12, 13])
    ap.add_argument("--range", type=int, nargs=2, default=None, metavar=("FIRST", "LAST"))
    ap.add_argument("--zero-shot", action="store_true", help="the design before refinement")
    args = ap.parse_args()
    quick = {"refine": False, "hedge": 0, "fallback": 0} if args.zero_shot else {}
    effort = mi.Effort(seed=0, **quick)
    if args.range:
        args.seeds = list(range(args.range[0], args.range[1] + 1))
    errors, f0_errors = [], []
    print("| law (seed) | curve error | F_0 note | seconds |")
    print("| --- | ---: | --- | ---: |")
    with tempfile.TemporaryDirectory() as tmp:
        for seed in args.seeds:
            p, a = adhesive_cell_curve(W_J / (E * R), seed=seed, rows=24)
            path = Path(tmp) / f"law{seed}.csv"
            path.write_text(
                "normal_force,friction_force\n"
                + "".join(
                    f"{x:.12g},{y:.12g}\n"
                    for x, y in zip(p * AREA * E, a * TAU * AREA, strict=True)
                )
            )
            t = mi.Target.from_friction(
                path,
                work_of_adhesion="50mJ/m2",
                shear_strength=TAU,
                modulus=E,
                radius=R,
                area=AREA,
                fit="never",
            )
            start = time.perf_counter()
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                r = mi.design(t, verify=False, effort=effort)
            note = next((n for n in r.notes if "friction at zero load" in n), "-")
            errors.append(100 * r.error)
            share = re.search(r"\(([+-][\d.e+-]+) %\)$", note)  # the note's "(+25.3 %)"
            if share:
                f0_errors.append(abs(float(share.group(1))))
            print(
                f"| {seed} | {100 * r.error:.2f} % | {note} | {time.perf_counter() - start:.1f} |"
            )

    if len(errors) > 1:
        print(
            f"\n{len(errors)} laws: curve error median {statistics.median(errors):.2f} %, "
            f"max {max(errors):.2f} %; |F_0 error| median {statistics.median(f0_errors):.1f} %, "
            f"max {max(f0_errors):.1f} % ({len(f0_errors)} stated)"
        )


if __name__ == "__main__":
    main()
