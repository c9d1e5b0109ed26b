"""Designs checked and corrected in BEM (issue 27): how far the made surface is from the law.

Targets: the three built-ins, --n-random held-out realisable targets (exact model curves of
random cells, gamma uniform in the bounds and h uniform in [0, Delta_max], seed --seed: not
the training set's generator or seed) and five analytic laws. Each target is designed with
the CLI's defaults (surrogate, hedge 8, fallback 50; verify=False), then, at each grid of
--grids, checked in BEM at --loads loads over the target's range (``verify.bem_check``) and
corrected there (``verify.correct``, up to --iterations BEM solves, re-refined on the
--inner model, with a fresh design per iteration unless --no-restart; ``--inner design
--no-restart`` is the first scheme: the design's own model, from the kept design). With
--cross, a design corrected at the first grid is also measured at the last one (does the
correction carry to the finer grid, or did it fit the coarse grid's own error?).

Columns: the model error (on the refinement's 128-point grid), the BEM error before and
after correction per grid (after: read at the loads (k - 1/2) / K between the k / K the
correction fitted; each with the check's accuracy), the corrected design's model error, and
the wall time of the design and of the BEM work per grid. (Before issue 53 "after" was read
at the fitted loads, on the grid's own reading, without extrapolation.)

Run: python benchmarks/bench_verified.py [--grids 384 768] [--n-random 30] [--loads 10]
     [--iterations 3] [--inner interacting] [--no-restart] [--engine torch] [--device auto]
     [--cross] [--out results/verified.md]
     python benchmarks/bench_verified.py --quick    (192^2, 6 loads, 3 random targets)
"""

import argparse
import json
import os
import sys
import time
from pathlib import Path

import numpy as np
import torch
from tqdm import tqdm

import metainterface as mi
from metainterface._threads import threads_for
from metainterface.runtime import tune_allocator
from metainterface.verify import Verify, bem_check, correct

sys.path.insert(0, str(Path(__file__).parent))
from bench_design import realisable_targets

#: Seed of the held-out random cells (the training set is the data categories' generator).
HELD_OUT_SEED = 2027


def analytic_laws() -> list[mi.Target]:
    """Five laws in the range of the paper's cell (P* up to 0.002, alpha a few %)."""
    p = np.linspace(0.0, 0.002, 128)
    laws = {
        "sqrt": 0.05 * np.sqrt(p / 0.002),
        "power-0.75": 0.05 * (p / 0.002) ** 0.75,
        "linear-15": 15.0 * p,
        "exp-saturating": 0.06 * (1.0 - np.exp(-p / 6e-4)),
        "log": 0.05 * np.log1p(p / 2e-4) / np.log1p(10.0),
    }
    return [mi.Target(p_star=p, alpha=a, name=n, source="analytic") for n, a in laws.items()]


def run_target(r, grids: list[int], args: argparse.Namespace) -> dict:
    """One designed target checked and corrected at every grid, on the threads the package
    picks for that work (as ``mi.design(..., verify=...)`` runs it): the check and the
    correction are called here below the public API, which makes that choice (on torch's
    default two threads, with two busy processes beside, ``--quick`` ran past 300 s where
    it now takes 220 s)."""
    with threads_for():
        return _run_target(r, grids, args)


def _run_target(r, grids: list[int], args: argparse.Namespace) -> dict:
    row = {
        "target": r.target.name,
        "kind": "analytic" if r.target.source == "analytic" else "realisable",
        "model_error": r.error,
        "design_seconds": r.seconds,
    }
    first = None
    for g in grids:
        s = Verify(
            grid=g,
            loads=args.loads,
            correct=True,
            iterations=args.iterations,
            inner=None if args.inner == "design" else args.inner,
            restart=not args.no_restart,
            engine=args.engine,
            device=args.device,
        )
        t0 = time.perf_counter()
        before = bem_check(r.design, r.target, s, r.model)
        fixed = correct(r.design, r.target, before, s, r.model)
        # the corrected design's error read at the loads between those it was fitted at
        after = fixed.check
        if fixed.check is not before:
            after = bem_check(fixed.design, r.target, s, r.model, held_out=True)
        row[g] = {
            "bem_before": before.bem_error,
            "accuracy_before": before.accuracy,
            "model_error_at_loads": before.model_error,
            "bem_fitted": fixed.check.bem_error,
            "bem_after": after.bem_error,
            "accuracy_after": after.accuracy,
            "model_error_after": fixed.model_error,
            "iterations": len(fixed.corrections),
            "kept": sum(c.accepted for c in fixed.corrections),
            "seconds": time.perf_counter() - t0,
            "check_seconds": before.seconds,
        }
        row["engine"] = f"{before.engine} ({before.device})"
        if first is None:
            first = fixed
    if args.cross and len(grids) > 1 and first is not None:
        top = Verify(grid=grids[-1], loads=args.loads, engine=args.engine, device=args.device)
        row["cross"] = bem_check(first.design, r.target, top, r.model).bem_error
    return row


def pc(x: float) -> str:
    return f"{100 * x:.2f} %"


def pm(accuracy: float | None) -> str:
    """' +- 0.15 %', or '' where the check could not estimate its accuracy."""
    return "" if accuracy is None else f" +- {pc(accuracy)}"


def table(rows: list[dict], grids: list[int], cross: bool) -> str:
    head = ["target", "model error"]
    for g in grids:
        head += [f"BEM {g}^2 before", "after (held-out loads)", "model error after", f"BEM s {g}^2"]
    if cross:
        head.append(f"corrected at {grids[0]}^2, BEM {grids[-1]}^2")
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for row in rows:
        cells = [row["target"], pc(row["model_error"])]
        for g in grids:
            c = row[g]
            cells += [
                pc(c["bem_before"]) + pm(c["accuracy_before"]),
                pc(c["bem_after"]) + pm(c["accuracy_after"]),
                pc(c["model_error_after"]),
                f"{c['seconds']:.1f}",
            ]
        if cross:
            cells.append(pc(row["cross"]) if "cross" in row else "")
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines)


def summary(rows: list[dict], grids: list[int]) -> list[str]:
    out = []
    groups = {
        "realisable (built-in bilinear, saturating and the random ones)": [
            r for r in rows if r["kind"] != "analytic" and r["target"] != "linear"
        ],
        "analytic laws (and the built-in linear)": [
            r for r in rows if r["kind"] == "analytic" or r["target"] == "linear"
        ],
    }
    for name, group in groups.items():
        if not group:
            continue
        for g in grids:
            b = np.array([r[g]["bem_before"] for r in group])
            a = np.array([r[g]["bem_after"] for r in group])
            m = np.array([r[g]["model_error_at_loads"] for r in group])
            out.append(
                f"- {name}, {g}^2: BEM error median {pc(np.median(b))} -> {pc(np.median(a))} "
                f"after correction, max {pc(b.max())} -> {pc(a.max())}; <= 0.5 % after: "
                f"{int((a <= 0.005).sum())} of {a.size}; BEM within the model's error + 0.2 "
                f"points after: {int((a <= m + 0.002).sum())} of {a.size}"
            )
    return out


# Quick mode (`python benchmarks/run.py run --quick`, CI): seconds, same code paths.
QUICK = "--quick --grids 96 --loads 4 --n-random 1 --no-analytic --only saturating --iterations 1"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    ap.add_argument("--grids", type=int, nargs="+", help="(384 768)")
    ap.add_argument("--n-random", type=int, help="held-out random targets (30)")
    ap.add_argument("--loads", type=int, help="loads of each check (10)")
    ap.add_argument("--iterations", type=int, default=3, help="BEM solves of a correction (3)")
    ap.add_argument(
        "--inner",
        default="interacting",
        help="the correction's model: interacting (default), independent, or design (the "
        "design's own)",
    )
    ap.add_argument(
        "--no-restart",
        action="store_true",
        help="the correction only re-refines the kept design (no fresh design per iteration)",
    )
    ap.add_argument("--engine", default="torch", help="contact solver (torch)")
    ap.add_argument("--device", default="auto", help="torch engine's device (auto)")
    ap.add_argument("--no-analytic", action="store_true", help="leave out the analytic laws")
    ap.add_argument("--only", nargs="+", metavar="NAME", help="check only these targets")
    ap.add_argument(
        "--cross", action="store_true", help="measure the first grid's correction on the last grid"
    )
    ap.add_argument("--quick", action="store_true", help="192^2, 6 loads, 3 random targets")
    ap.add_argument("--out", help="write the markdown here (and the rows as .json beside)")
    args = ap.parse_args()
    quick = {"grids": [192], "loads": 6, "n_random": 3}
    full = {"grids": [384, 768], "loads": 10, "n_random": 30}
    for key, value in (quick if args.quick else full).items():  # what was not given
        if getattr(args, key) is None:
            setattr(args, key, value)
    tune_allocator()
    targets = [mi.Target.builtin(n) for n in mi.Target.builtins()]
    targets += realisable_targets(args.n_random, seed=HELD_OUT_SEED)
    if not args.no_analytic:
        targets += analytic_laws()
    if args.only:
        targets = [t for t in targets if t.name in args.only]
    t0 = time.perf_counter()
    designs = mi.design(targets, verify=False)
    t_design = time.perf_counter() - t0
    rows = []
    for r in tqdm(designs, desc="BEM check + correct"):
        rows.append(run_target(r, args.grids, args))
        if args.out:  # the rows so far, so a long run that is stopped still leaves them
            Path(args.out).with_suffix(".json").write_text(json.dumps(rows, indent=1, default=str))
    text = table(rows, args.grids, args.cross)
    notes = summary(rows, args.grids)
    threads = torch.get_num_threads()
    command = "python benchmarks/bench_verified.py " + " ".join(sys.argv[1:])
    md = "\n".join(
        [
            "# Designs checked and corrected in BEM (issue 27)",
            "",
            f"`{command}`; torch {torch.__version__}, {threads} threads, "
            f"OMP_NUM_THREADS={os.environ.get('OMP_NUM_THREADS', 'unset')}, engine "
            f"{rows[0]['engine']}, {args.loads} loads, correction up to "
            f"{args.iterations} BEM solves on the {args.inner} model"
            f"{' without' if args.no_restart else ' with'} fresh designs. {len(targets)} targets "
            f"designed in one call in {t_design:.1f} s.",
            "",
            text,
            "",
            *notes,
            "",
        ]
    )
    print(md)
    if args.out:
        out = Path(args.out)
        out.write_text(md)
        out.with_suffix(".json").write_text(json.dumps(rows, indent=1, default=str))


if __name__ == "__main__":
    main()
