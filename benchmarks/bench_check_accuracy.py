"""The BEM check's own accuracy against an independent solver on a finer grid (issue 53).

Held-back targets (exact model curves of --count random cells, gamma uniform in the bounds
and h uniform in [0, Delta_max], seed --seed: not the training set's, not the correction's
tuning set's (seed 2027, bench_verified.py) and not the cells the check's convergence order
was measured on (seed 5353, --convergence)) are designed with the default check
(``mi.design(targets)``: torch, 384^2 extrapolated with 192^2, 10 loads, correction where
it pays). Each design is then solved in Tamaas on a grid twice as fine as the check's, at
loads the check did not use: top (k - 1/4) / K, k = 1..K (the check fits k / K and reports
a corrected design at (k - 1/2) / K). Printed per target: the error the design reports and
its accuracy, and its error in Tamaas; then the count within 0.5 %, the median and the
largest, and how many Tamaas errors lie within the reported error +- its accuracy.

--convergence: the measurement behind ``verify.accuracy.ORDER``: --count cells of seed
5353 solved in torch at 192^2, 384^2 and 768^2 at the check's loads; the norm of the
differences of successive grids, the order p they give, and the extrapolation from 192^2
and 384^2 against the 768^2 solve.

Run: python benchmarks/bench_check_accuracy.py [--count 4] [--seed 5331] [--out FILE.md]
     python benchmarks/bench_check_accuracy.py --builtins saturating   (the README's main job)
     python benchmarks/bench_check_accuracy.py --convergence [--count 4]
     python benchmarks/bench_check_accuracy.py --quick   (2 targets, check at 96^2 with one
         correction iteration at most, Tamaas 192^2)
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

import numpy as np
import torch

import metainterface as mi
from metainterface.physics.registry import get_model
from metainterface.verify.accuracy import ORDER, extrapolate
from metainterface.verify.check import Verify, check_loads, curve_error, solve_bem

sys.path.insert(0, str(Path(__file__).parent))
from bench_design import realisable_targets

#: Seed of the held-back cells (used for nothing else).
HELD_BACK_SEED = 5331
#: Seed of the cells the convergence order was measured on.
ORDER_SEED = 5353


def pc(x: float | None) -> str:
    return "n/a" if x is None else f"{100 * x:.2f} %"


def reference_loads(check: mi.BemCheck, k: int) -> np.ndarray:
    """(K,) top (k - 1/4) / K: neither the check's k / K nor its held-out (k - 1/2) / K."""
    top = check.p_star[-1] * (k / (k - 0.5)) if check.held_out else check.p_star[-1]
    return top * (np.arange(1, k + 1) - 0.25) / k


def held_back(args: argparse.Namespace) -> str:
    if args.builtins:  # not held back: the built-ins tuned the correction (bench_verified)
        targets = [mi.Target.builtin(n) for n in args.builtins]
    else:
        targets = realisable_targets(args.count, seed=args.seed)
    # quick: one correction iteration at most (96^2 cannot estimate its accuracy, so the
    # correction would spend all of its iterations there)
    quick = {"grid": 96, "iterations": 1} if args.quick else {}
    verify = Verify(loads=args.loads, **quick)
    rows = []
    for t in targets:  # one call each, as a user designs one law
        t0 = time.perf_counter()
        r = mi.design(t, verify=verify)
        seconds = time.perf_counter() - t0
        b = r.bem
        fine = 2 * b.grid
        loads = reference_loads(b, args.loads)
        ref = solve_bem(r.design, loads, Verify(grid=fine, engine="tamaas"), get_model(r.model))
        alpha_t = np.interp(loads, r.target.p_star, r.target.alpha)
        rows.append(
            {
                "target": t.name,
                "model_error": b.model_error,
                "bem_error": b.bem_error,
                "accuracy": b.accuracy,
                "held_out": b.held_out,
                "corrected": r.bem_before is not None and r.bem is not r.bem_before,
                "iterations": len(r.corrections),
                "before": (r.bem_before or b).bem_error,
                "tamaas": curve_error(ref.alpha_bem, alpha_t),
                "grid": b.grid,
                "fine": fine,
                "seconds": seconds,
                "tamaas_seconds": ref.seconds,
            }
        )
        print(rows[-1], flush=True)
    head = (
        "| target | check before | corrected (iterations) | reported BEM error +- accuracy "
        f"(loads) | Tamaas {rows[0]['fine']}^2 at (k - 1/4) / K | within 0.5 % | within "
        "reported +- accuracy | design s | Tamaas s |"
    )
    lines = [head, "|" + "---|" * 9]

    def within(w: dict) -> bool:
        # a check too coarse to estimate its accuracy (accuracy None) holds nothing
        return w["accuracy"] is not None and abs(w["tamaas"] - w["bem_error"]) <= w["accuracy"]

    for w in rows:
        inside = within(w)
        lines.append(
            f"| {w['target']} | {pc(w['before'])} | {'yes' if w['corrected'] else 'no'} "
            f"({w['iterations']}) | {pc(w['bem_error'])} +- {pc(w['accuracy'])} "
            f"({'(k - 1/2) / K' if w['held_out'] else 'k / K'}) | {pc(w['tamaas'])} | "
            f"{'yes' if w['tamaas'] <= 0.005 else 'NO'} | {'yes' if inside else 'no'} | "
            f"{w['seconds']:.0f} | {w['tamaas_seconds']:.0f} |"
        )
    tam = np.array([w["tamaas"] for w in rows])
    inside = sum(within(w) for w in rows)
    lines += [
        "",
        f"Tamaas {rows[0]['fine']}^2 error to the target: within 0.5 % {int((tam <= 0.005).sum())}"
        f" of {tam.size}, median {pc(float(np.median(tam)))}, largest {pc(float(tam.max()))}; "
        f"within the reported error +- its accuracy: {inside} of {tam.size} (a loose test: "
        f"the loads differ, and the {rows[0]['fine']}^2 grid has its own error).",
    ]
    return "\n".join(lines)


def convergence(args: argparse.Namespace) -> str:
    targets = realisable_targets(args.count, seed=ORDER_SEED)
    lines = [
        "| target | norm 192-384 | norm 384-768 | ratio | order p | extrapolated (p = "
        f"{ORDER}) vs 768^2 | 384^2 vs 768^2 |",
        "|" + "---|" * 7,
    ]
    for r in mi.design(targets, verify=False):
        fm = get_model(r.model)
        loads = check_loads(r.design, r.target, fm, args.loads)
        a = {g: solve_bem(r.design, loads, Verify(grid=g), fm).alpha_bem for g in (192, 384, 768)}
        norm = np.linalg.norm(np.interp(loads, r.target.p_star, r.target.alpha))
        d1 = np.linalg.norm(a[192] - a[384]) / norm
        d2 = np.linalg.norm(a[384] - a[768]) / norm
        ex = np.linalg.norm(extrapolate(a[384], a[192], 2.0) - a[768]) / norm
        lines.append(
            f"| {r.target.name} | {pc(d1)} | {pc(d2)} | {d1 / d2:.2f} | "
            f"{np.log2(d1 / d2):.2f} | {pc(ex)} | {pc(d2)} |"
        )
        print(lines[-1], flush=True)
    return "\n".join(lines)


# Quick mode (`python benchmarks/run.py run --quick`, CI): seconds, same code paths.
QUICK = "--quick --count 1"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    ap.add_argument("--count", type=int, default=None, help="targets (4; --quick: 2)")
    ap.add_argument("--seed", type=int, default=HELD_BACK_SEED, help="held-back cells' seed")
    ap.add_argument("--loads", type=int, default=10, help="loads of the check (10)")
    ap.add_argument("--convergence", action="store_true", help="measure the grids' order")
    ap.add_argument(
        "--builtins", nargs="+", metavar="NAME", help="built-in targets instead (not held back)"
    )
    ap.add_argument("--quick", action="store_true", help="2 targets, 96^2 check, Tamaas 192^2")
    ap.add_argument("--out", help="write the markdown here")
    args = ap.parse_args()
    if args.quick:
        args.loads = 4
    args.count = args.count or (2 if args.quick else 4)
    command = "python benchmarks/bench_check_accuracy.py " + " ".join(sys.argv[1:])
    text = convergence(args) if args.convergence else held_back(args)
    md = "\n".join(
        [
            f"`{command}`; torch {torch.__version__}, OMP_NUM_THREADS="
            f"{os.environ.get('OMP_NUM_THREADS', 'unset')}, {os.cpu_count()} CPUs (shared).",
            "",
            text,
            "",
        ]
    )
    print(md)
    if args.out:
        Path(args.out).write_text(md)


if __name__ == "__main__":
    main()
