"""An offset friction law's F_0 (issue 38): held-back PDMS laws designed with the work of
adhesion, their curve error and their friction at zero load against the law's.

Each law is a held-back adhesive cell's loading curve (``adhesive_cell_curve``, 24 rows
from zero load) as a friction law over 4 cm^2 (tau 0.3 MPa, E* 2.4 MPa, R 0.5 mm, w 50
mJ/m^2), designed by the default path without the BEM check. The curve error weighs the
zero-load row as one point of many; F_0 is computed here for every law: the design's by its
forward model at zero load, the law's from its own zero-load row (not read from the note).
The offset polish's settings and the adhesive fallback threshold were chosen on seeds 11-30;
``--held-out`` designs seeds 31-50, on which nothing was chosen. Every run states which.

    PYTHONPATH=src python benchmarks/bench_offset_f0.py [--seeds 11 12 13] [--range 11 30]
        [--held-out] [--zero-shot]

Ends with the median and largest curve error and |F_0 error| over the laws (``--range A B``:
the seeds A..B). ``--zero-shot``: the design before its refinement, as
``bench_friction_laws.py`` measures it (``Effort(refine=False, hedge=0, fallback=0)``).
"""

from __future__ import annotations

import argparse
import tempfile
import time
import warnings
from pathlib import Path

import numpy as np
import torch

import metainterface as mi
from metainterface._testing import adhesive_cell_curve

E, R, W_J, TAU, AREA = 2.4e6, 0.5e-3, 0.05, 0.3e6, 4e-4
#: The laws the offset polish's settings (zero-load weight 256, curve slack 10 %, count steps)
#: and the adhesive fallback threshold (1 %) were chosen on (results/adhesion.md).
TUNED_ON = range(11, 31)
#: Laws none of those settings was chosen on: ``--held-out`` designs these.
HELD_OUT = range(31, 51)


def law_f0(seed: int) -> tuple[float, np.ndarray, np.ndarray]:
    """The law of ``seed``: (F_0 [N], p_star (24,), alpha (24,)); F_0 the law's own
    friction at its first row, which is zero load."""
    p, a = adhesive_cell_curve(W_J / (E * R), seed=seed, rows=24)
    if p[0] != 0:
        raise SystemExit(f"law {seed}: its first row is at P* = {p[0]:g}, not at zero load")
    return float(a[0]) * TAU * AREA, p, a


def design_f0(r) -> float:
    """The design's friction at zero load [N], by its own forward model: alpha at a load
    of 1e-12 of the target's largest (zero load as the rising force first holds it)."""
    gamma, h = (torch.atleast_2d(v) for v in r.design.tensors(torch.float64))
    tiny = torch.tensor([[1e-12 * float(r.target.p_star_max)]], dtype=torch.float64)
    with torch.no_grad():
        alpha = r.model.alpha_at_loads(gamma, h, r.design.settings, tiny)
    return float(alpha[0, 0]) * TAU * AREA


def describe(seeds: list[int]) -> str:
    """Which of ``seeds`` the settings were chosen on, which are held out."""
    tuned = [s for s in seeds if s in TUNED_ON]
    held = len(seeds) - len(tuned)
    return (
        f"laws (seeds) {seeds[0]}..{seeds[-1]}: {held} held out, {len(tuned)} of the set the "
        f"settings were chosen on (seeds {TUNED_ON.start}-{TUNED_ON.stop - 1})"
    )


# Quick mode (`python benchmarks/run.py run --quick`, CI): seconds, same code paths.
QUICK = "--seeds 31 --zero-shot"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, nargs="+", default=[11, 12, 13])
    ap.add_argument("--range", type=int, nargs=2, default=None, metavar=("FIRST", "LAST"))
    ap.add_argument(
        "--held-out",
        action="store_true",
        help=f"the laws {HELD_OUT.start}-{HELD_OUT.stop - 1}, on which no setting was chosen",
    )
    ap.add_argument("--zero-shot", action="store_true", help="the design before refinement")
    args = ap.parse_args()
    quick = {"refine": False, "hedge": 0, "fallback": 0} if args.zero_shot else {}
    effort = mi.Effort(seed=0, **quick)
    if args.range:
        args.seeds = list(range(args.range[0], args.range[1] + 1))
    if args.held_out:
        args.seeds = list(HELD_OUT)
    errors, f0_errors = [], []
    print(describe(args.seeds))
    print("| law (seed) | curve error | F_0 design | F_0 law | F_0 error | seconds |")
    print("| --- | ---: | ---: | ---: | ---: | ---: |")
    with tempfile.TemporaryDirectory() as tmp:
        for seed in args.seeds:
            f0_law, p, a = law_f0(seed)
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
            f0 = design_f0(r)
            errors.append(100 * r.error)
            f0_errors.append(100 * abs(f0 / f0_law - 1))
            print(
                f"| {seed} | {100 * r.error:.2f} % | {f0:.3g} N | {f0_law:.3g} N | "
                f"{100 * (f0 / f0_law - 1):+.2f} % | {time.perf_counter() - start:.1f} |",
                flush=True,
            )
    e, f = np.array(errors), np.array(f0_errors)
    print(
        f"\n{e.size} laws: curve error median {np.median(e):.2f} %, max {e.max():.2f} %, "
        f"within 2 %: {int((e <= 2).sum())} of {e.size}; |F_0 error| median "
        f"{np.median(f):.2f} %, max {f.max():.2f} %, within 1 %: {int((f <= 1).sum())} of {f.size}"
    )


if __name__ == "__main__":
    main()
