"""Robust design against nominal design under the same manufacturing errors (issue 20).

Each target is designed twice with the CLI's defaults (surrogate, 8 hedge starts, 50-start
fallback): nominally, and robustly (``robust=True``: the mean error over --copies perturbed
copies of every start). Both designs are then made --samples times with the same
perturbations (independent of those the robust design was refined against: another seed)
and their relative curve errors to the target compared: median and p95 per design, and over
the targets. Targets: the three built-ins and --targets realisable ones (exact curves of
random cells, as in bench_design.py). Errors: sigma_h = --sigma-h [units of R] (0.002 R is
1 um at R = 0.5 mm, a tenth of Delta_max), sigma_gamma = --sigma-gamma.

Run: python benchmarks/bench_robust.py [--targets 10] [--copies 16] [--out results/robust.md]
"""

import argparse
import sys
import time
from pathlib import Path

import numpy as np
import torch

import metainterface as mi
from metainterface.inverse.perturb import Perturbation
from metainterface.inverse.scatter import spread
from metainterface.runtime import tune_allocator

sys.path.insert(0, str(Path(__file__).parent))
from bench_design import realisable_targets


def made_errors(results, pert: Perturbation) -> np.ndarray:
    """(T, S) relative errors of each design's made cells to its target."""
    rows = []
    for r in results:
        d = r.design
        s = spread(
            d.gamma,
            d.h,
            d.settings,
            r.model,
            pert,
            target=(r.target.p_star, r.target.alpha),
            linear=False,
        )
        rows.append(s.errors)
    return np.array(rows)


# Quick mode (`python benchmarks/run.py run --quick`, CI): seconds, same code paths.
QUICK = "--builtins saturating --targets 0 --copies 2 --samples 16 --no-verify"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument(
        "--targets", type=int, default=10, help="realisable targets (10; the table: 50)"
    )
    ap.add_argument("--copies", type=int, default=16, help="robust_samples K (16)")
    ap.add_argument("--samples", type=int, default=1024, help="made cells per design (1024)")
    ap.add_argument("--sigma-h", type=float, default=0.002, help="height error [R] (0.002)")
    ap.add_argument("--sigma-gamma", type=float, default=0.05, help="shape error (0.05)")
    ap.add_argument("--out", help="write the markdown table here")
    ap.add_argument("--builtins", nargs="*", metavar="NAME", help="default: all built-ins")
    ap.add_argument("--no-verify", action="store_true", help="designs without the BEM check")
    args = ap.parse_args()
    tune_allocator()
    names = mi.Target.builtins() if args.builtins is None else args.builtins
    targets = [mi.Target.builtin(n) for n in names]
    targets += realisable_targets(args.targets) if args.targets else []
    verify = {"verify": False} if args.no_verify else {}
    mi.design(targets[:1], **verify)  # warm-up (imports, model load)
    t0 = time.perf_counter()
    nominal = mi.design(targets, **verify)
    t_nom = time.perf_counter() - t0
    t0 = time.perf_counter()
    robust = mi.design(
        targets,
        robust=mi.Robust(samples=args.copies, sigma_h=args.sigma_h, sigma_gamma=args.sigma_gamma),
        **verify,
    )
    t_rob = time.perf_counter() - t0
    pert = Perturbation.draw(
        9, args.samples, 12345, sigma_h=args.sigma_h, sigma_gamma=args.sigma_gamma
    )
    with torch.no_grad():
        e_nom, e_rob = made_errors(nominal, pert), made_errors(robust, pert)
    p95_nom, p95_rob = np.quantile(e_nom, 0.95, axis=1), np.quantile(e_rob, 0.95, axis=1)
    med_nom, med_rob = np.median(e_nom, axis=1), np.median(e_rob, axis=1)

    def pc(x: float) -> str:
        return f"{100 * x:.2f} %"

    lines = [
        "# Robust design against nominal design (issue 20)",
        "",
        f"`python benchmarks/bench_robust.py --targets {args.targets} --copies {args.copies} "
        f"--samples {args.samples} --sigma-h {args.sigma_h} --sigma-gamma {args.sigma_gamma}"
        f"{' --out ' + args.out if args.out else ''}`; torch {torch.__version__}, "
        f"{torch.get_num_threads()} threads. Errors: sigma_h = {args.sigma_h} R "
        f"({args.sigma_h / 0.02:.2g} Delta_max; 1 um at R = 0.5 mm for 0.002), sigma_gamma = "
        f"{args.sigma_gamma}; each design made {args.samples} times with the same draws "
        "(another seed than the robust design's copies). Designs: CLI defaults (surrogate, "
        f"hedge 8, fallback 50); robust: `robust=True, robust_samples={args.copies}`.",
        "",
        "| target | nominal: design error | made median | made p95 "
        "| robust: design error | made median | made p95 |",
        "|---|---|---|---|---|---|---|",
    ]
    for i in range(len(names)):
        lines.append(
            f"| {targets[i].name} | {pc(nominal[i].error)} | {pc(med_nom[i])} | "
            f"{pc(p95_nom[i])} | {pc(robust[i].error)} | {pc(med_rob[i])} | {pc(p95_rob[i])} |"
        )
    rnd = slice(len(names), None)
    if args.targets:
        en = np.array([r.error for r in nominal[rnd]])
        er = np.array([r.error for r in robust[rnd]])
        lines.append(
            f"| {args.targets} realisable (median over targets) | {pc(np.median(en))} | "
            f"{pc(np.median(med_nom[rnd]))} | {pc(np.median(p95_nom[rnd]))} | "
            f"{pc(np.median(er))} | {pc(np.median(med_rob[rnd]))} | "
            f"{pc(np.median(p95_rob[rnd]))} |"
        )
    better = p95_rob < p95_nom
    ratio = p95_rob / p95_nom
    lines += [
        "",
        f"Robust p95 below nominal p95 on {int(better.sum())} of {len(targets)} targets; "
        f"p95 ratio robust / nominal: median {np.median(ratio):.3f}, "
        f"range {ratio.min():.3f}-{ratio.max():.3f}.",
        "",
        f"Time for all {len(targets)} targets in one call: nominal {t_nom:.1f} s "
        f"({t_nom / len(targets):.2f} s per target), robust {t_rob:.1f} s "
        f"({t_rob / len(targets):.2f} s per target), {t_rob / t_nom:.1f}x.",
    ]
    text = "\n".join(lines) + "\n"
    print(text)
    if args.out:
        Path(args.out).write_text(text, encoding="utf-8")


if __name__ == "__main__":
    main()
