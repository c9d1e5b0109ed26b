"""Design with adhesion (issue 38, item 2): the shipped surrogate's zero-shot error on
adhesive targets, and after the refinement with the adhesive model.

Held-back cells (random gamma in [1.8, 4], heights in [0, 0.6] Delta_max, seeds 100..)
give their loading curves under Independent(adhesion=w) (w = 4.2e-5 E* R: PDMS on glass
at R = 0.5 mm) and, for comparison, without adhesion. Each target is designed by the
default path without the refinement (zero-shot: the shipped networks' readings, among them
the adhesive network's where weights/surrogate_adhesive.pt is there, scored with the
adhesive model) and with it. No BEM check (verify=False).

    PYTHONPATH=src python benchmarks/bench_adhesive_design.py [--targets 8]
        [--models adhesive plain] [--alone MODEL_FILE [--hedge 4]] [--zero-shot]

``--alone FILE``: that network alone, zero-shot (no refinement, no fallback), ``--hedge`` its
hedges (design's default 8).
"""

from __future__ import annotations

import argparse
import time
import warnings

import numpy as np
import torch

import metainterface as mi
from metainterface.physics import CellSettings

W = 4.2e-5


def target(model, g, h, s, name):
    gt, ht = torch.as_tensor(g)[None], torch.as_tensor(h)[None]
    with torch.no_grad():
        p_max = float(model.sweep(gt, ht, s, n_delta=2049).p_star[0, -1])
        p = np.linspace(0, p_max, 64)
        p[0] = 1e-12 * p_max
        a = model.alpha_at_loads(gt, ht, s, torch.as_tensor(p)[None])[0].numpy()
    p[0] = 0.0
    return mi.Target(p_star=p, alpha=a, name=name)


# Quick mode (`python benchmarks/run.py run --quick`, CI): seconds, same code paths.
QUICK = "--targets 1 --models adhesive --zero-shot"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--targets", type=int, default=8)
    parser.add_argument(
        "--models", nargs="+", choices=["adhesive", "plain"], default=["adhesive", "plain"]
    )
    parser.add_argument("--alone", metavar="MODEL_FILE", help="this network alone, zero-shot")
    parser.add_argument("--hedge", type=int, help="with --alone: its hedges")
    parser.add_argument("--zero-shot", action="store_true", help="without the refined designs")
    args = parser.parse_args()
    if args.alone:
        hedge = {} if args.hedge is None else {"hedge": args.hedge}
        efforts = {
            False: mi.Effort(seed=0, refine=False, fallback=0, surrogate=args.alone, **hedge)
        }
    else:
        refines = (False,) if args.zero_shot else (False, True)
        efforts = {refine: mi.Effort(refine=refine, seed=0) for refine in refines}
    s = CellSettings()
    rows = {}
    models = {"adhesive": mi.Independent(adhesion=W), "plain": mi.Independent()}
    for label, model in ((k, models[k]) for k in args.models):
        for refine, effort in efforts.items():
            errs, secs = [], []
            for k in range(args.targets):
                rng = np.random.default_rng(100 + k)
                g = rng.uniform(1.8, 4.0, 9)
                h = rng.uniform(0, 0.6, 9) * s.delta_max
                h -= h.min()
                t = target(model, g, h, s, f"{label}{k}")
                start = time.perf_counter()
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore")
                    r = mi.design(t, model=model, verify=False, effort=effort)
                secs.append(time.perf_counter() - start)
                errs.append(r.error)
            key = f"{label:8s} {'refined' if refine else 'zero-shot'}"
            rows[key] = errs
            e = np.array(errs)
            print(
                f"{key:20s} median {100 * np.median(e):.2f} %  max {100 * e.max():.2f} %  "
                f"<=2 %: {int((e <= 0.02).sum())}/{e.size}  ({np.mean(secs):.1f} s each)",
                flush=True,
            )


if __name__ == "__main__":
    main()
