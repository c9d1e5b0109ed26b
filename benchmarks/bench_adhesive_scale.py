"""The scale of an offset friction law with adhesion (issue 38, item 3): what
``feasible_scale`` and ``design_scale`` cost with a work of adhesion, and what they find.

The law: a held-back adhesive cell's loading curve (PDMS on glass, w = 50 mJ/m^2, E* = 2.4
MPa, R = 0.5 mm, tau = 0.3 MPa) over 4 cm^2, with its zero-load row (F_f(0) = 1.96 N).
``feasible_scale`` at 1 cm^2 (out of reach: every variable searched; the modulus with an
envelope per value) and ``design_scale`` with area='auto' (verify=False).

    PYTHONPATH=src python benchmarks/bench_adhesive_scale.py [--area 1cm2]
        [--design-area auto|RANGE|skip]
"""

from __future__ import annotations

import argparse
import tempfile
import time
import warnings
from pathlib import Path

import metainterface as mi
from _held_back import write_law

UNITS = dict(shear_strength="0.3MPa", modulus="2.4MPa", radius="0.5mm", fit="never")


def law(folder: Path) -> Path:
    return write_law(folder / "pdms.csv")


# Quick mode (`python benchmarks/run.py run --quick`, CI): seconds, same code paths.
QUICK = "--area 4cm2 --design-area skip"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--area", default="1cm2", help="feasible_scale's area (1cm2)")
    ap.add_argument(
        "--design-area", default="auto", help="design_scale's area: auto, a range, or 'skip'"
    )
    args = ap.parse_args()
    csv = law(Path(tempfile.mkdtemp()))
    start = time.perf_counter()
    fs = mi.feasible_scale(csv, area=args.area, work_of_adhesion="50mJ/m2", **UNITS)
    print(f"feasible_scale, {args.area}: {time.perf_counter() - start:.1f} s")
    for line in fs.summary():
        print("  " + line)
    if args.design_area == "skip":
        return
    start = time.perf_counter()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        r = mi.design_scale(
            csv, area=args.design_area, work_of_adhesion="50mJ/m2", verify=False, **UNITS
        )
    sc = r.target.meta["scale"]
    print(
        f"design_scale, area {args.design_area}: {time.perf_counter() - start:.1f} s; chose "
        f"{sc['value'] * 1e4:.3g} cm^2 (the law's own: 4 cm^2), error {100 * r.error:.2f} %, "
        f"model {r.model.label}"
    )


if __name__ == "__main__":
    main()
