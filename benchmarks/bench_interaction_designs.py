"""Designs made with each forward model, checked in BEM (issue 9, last target).

For the built-in targets saturating, bilinear and linear, `design` (surrogate method, CLI
defaults: hedge 8, fallback 50) runs once with ``--physics independent`` and once with
``--physics interacting``; each design is then solved by Tamaas at M x M (default 768) at 8
loads uniform up to the target's largest P* (within the design's reach). The figures, per
design: its target error as the design step reports it (the model's, on the target's
grid), and the relative error ||alpha - alpha_target|| / ||alpha_target|| at the 8 loads
of the design's own model and of the BEM.

Target: designs made with --physics interacting keep their target error in BEM. The BEM's
contact area has sub-pixel edges (``bem.contact_area``; the plain count of grid points in
contact reads alpha 1-3 % high at 768 x 768, and its error is given too).

BEM results are cached in benchmarks/results/interaction_designs_<M>.json with the designs,
so a run that is interrupted resumes, and a rerun only re-prints.
Run: python benchmarks/bench_interaction_designs.py [--grid 768] [--jobs 2] [--out FILE.md]
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np

from metainterface._files.atomic import write_text
from metainterface.inverse import builtin_target, design
from metainterface.physics import CellSettings, Design
from metainterface.runtime import tune_allocator
from metainterface.validation import plan_validation

RESULTS = Path(__file__).parent / "results"
TARGETS = ("saturating", "bilinear", "linear")
PHYSICS = ("independent", "interacting")
N_LOADS = 8


def run_case(target_name: str, model: str, grid: int, jobs: int) -> dict:
    """Design for one target with one model, then its BEM check; a JSON-ready record."""
    target = builtin_target(target_name)
    t0 = time.perf_counter()
    (res,) = design([target], "surrogate", model=model, hedge=8, fallback=50)
    design_seconds = time.perf_counter() - t0
    extras = {"target": {"p_star": target.p_star.tolist(), "alpha": target.alpha.tolist()}}
    cell = Design(gamma=res.gamma, h=res.h, settings=CellSettings(), extras=extras)
    probe = plan_validation(cell, grid, 1, model=model)  # the design's reach
    top = min(target.p_star_max, float(probe.loads[-1]))
    plan = plan_validation(
        cell, grid, top * np.arange(1, N_LOADS + 1) / N_LOADS, model=model, name=target_name
    )
    t1 = time.perf_counter()
    result = plan.solve(jobs)
    bem_error, model_error = result.target_errors()
    pixel_error = result.target_error(result.alpha_bem_pixels)
    return {
        "target": target_name,
        "physics": model,
        "gamma": res.gamma.tolist(),
        "h": res.h.tolist(),
        "design_error": res.error,
        "design_seconds": design_seconds,
        "p_star": result.p_star.tolist(),
        "alpha_bem": result.alpha_bem.tolist(),
        "alpha_model": result.alpha_model.tolist(),
        "alpha_bem_pixels": result.alpha_bem_pixels.tolist(),
        "bem_pixels_error_at_loads": pixel_error,
        "model_error_at_loads": model_error,
        "bem_error_at_loads": bem_error,
        "bem_vs_model_upper_half": result.max_rel_err_upper,
        "bem_seconds": time.perf_counter() - t1,
    }


# Quick mode (`python benchmarks/run.py run --quick`, CI): seconds, same code paths.
QUICK = "--grid 48 --jobs 1 --targets saturating --cache {tmp}"


def main() -> None:
    tune_allocator()
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    ap.add_argument("--grid", type=int, default=768, help="BEM grid M (multiple of 3)")
    ap.add_argument("--jobs", type=int, default=2, help="BEM processes per design")
    ap.add_argument("--targets", nargs="+", default=list(TARGETS), choices=TARGETS)
    ap.add_argument("--cache", default=str(RESULTS), help="folder of the BEM cache (results/)")
    ap.add_argument("--out", help="also write the table as Markdown to this file")
    args = ap.parse_args()
    cache_path = Path(args.cache) / f"interaction_designs_{args.grid}.json"
    cache = json.loads(cache_path.read_text()) if cache_path.exists() else {}
    lines = [
        "| target | designed with | design error | model error at the loads | "
        "BEM error at the loads | BEM vs model (upper half) | BEM error, pixel count |",
        "|---|---|---|---|---|---|---|",
    ]
    print(lines[0], flush=True)
    for name in args.targets:
        for physics in PHYSICS:
            key = f"{name}|{physics}"
            if "alpha_bem_pixels" not in cache.get(key, {}):  # older: the count only
                cache[key] = run_case(name, physics, args.grid, args.jobs)
                write_text(cache_path, json.dumps(cache, indent=1) + "\n")
            r = cache[key]
            lines.append(
                f"| {name} | {physics} | {100 * r['design_error']:.3f} % | "
                f"{100 * r['model_error_at_loads']:.2f} % | "
                f"{100 * r['bem_error_at_loads']:.2f} % | "
                f"{100 * r['bem_vs_model_upper_half']:.2f} % | "
                f"{100 * r['bem_pixels_error_at_loads']:.2f} % |"
            )
            print(lines[-1], flush=True)
    if args.out:
        head = [
            "# Designs checked in BEM (issue 9)",
            "",
            f"`python benchmarks/bench_interaction_designs.py {' '.join(sys.argv[1:])}`; "
            f"Tamaas PKR, {args.grid} x {args.grid}, {N_LOADS} loads up to the target's P*_max; "
            "errors are ||alpha - alpha_target|| / ||alpha_target|| at those loads.",
            "",
        ]
        write_text(args.out, "\n".join(head + lines) + "\n")


if __name__ == "__main__":
    main()
