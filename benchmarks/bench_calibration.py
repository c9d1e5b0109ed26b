"""Calibration of tau and w (issue 38, item 5): how often the reported 95 % ranges hold the
true values, on synthetic friction tests with 3 % multiplicative noise.

A sphere (R = 5 mm, 25 loads from -0.5 to 20 mN) and a made design (a held-back 9-asperity
cell of 0.5 mm asperities over 4 cm^2, 20 loads from 0 to 95 % of its largest), both on
PDMS (E* = 2.4 MPa, tau = 0.3 MPa, w = 50 mJ/m^2), one noise draw per seed.

    PYTHONPATH=src python benchmarks/bench_calibration.py [--seeds 40] [--sphere-seeds 200]

``--as-run`` (issue 52): sphere tests as a lab runs them, >= 200 of them: radii 2, 5 and
10 mm, scatter 1-5 %, 25 loads up to 60 mN either from a pull (pull rows, the first at
70-100 % of pull-off) or from zero load (no pull rows), w = 20-80 mJ/m^2, tau = 0.2-0.4
MPa (drawn per test, seeded), through ``calibrate_sphere`` as the CLI calls it. Prints how
often each 95 % range (the profile likelihood's) holds the truth, how often both do, and
the refusals.

    PYTHONPATH=src python benchmarks/bench_calibration.py --as-run [--per-cell 7]
"""

from __future__ import annotations

import argparse
import time

import numpy as np
import torch

import metainterface as mi
from metainterface.calibration import (
    calibrate_design,
    calibrate_sphere,
    design_friction,
    sphere_friction,
)
from metainterface.physics import CellSettings

E, TAU, W = 2.4e6, 0.3e6, 0.05
R_SPHERE, R_ASP, AREA = 5e-3, 0.5e-3, 4e-4


def coverage(fit, clean: np.ndarray, seeds: int, label: str) -> None:
    """Fit ``seeds`` noisy copies of ``clean``; print the share of 95 % ranges that hold
    the truth, the median relative standard errors and the median time a fit."""
    hit_t = hit_w = 0
    sig_t, sig_w, secs = [], [], []
    for seed in range(seeds):
        noisy = clean * (1 + 0.03 * np.random.default_rng(seed).standard_normal(clean.size))
        start = time.perf_counter()
        cal = fit(noisy)
        secs.append(time.perf_counter() - start)
        ci = cal.interval(0.95)
        hit_t += ci["tau"][0] <= TAU <= ci["tau"][1]
        hit_w += ci["work"][0] <= W <= ci["work"][1]
        sig_t.append(cal.tau_sigma / TAU)
        sig_w.append(cal.work_sigma / W)
    print(
        f"{label:8s} {seeds} seeds: 95 % range holds tau {100 * hit_t / seeds:.1f} %, "
        f"w {100 * hit_w / seeds:.1f} %; median standard error tau +-{100 * np.median(sig_t):.2g} "
        f"%, w +-{100 * np.median(sig_w):.2g} %; {np.median(secs):.2g} s a fit",
        flush=True,
    )


# Quick mode (`python benchmarks/run.py run --quick`, CI): seconds, same code paths.
QUICK = "--seeds 1 --sphere-seeds 3"


def as_run(per_cell: int) -> None:
    """Sphere tests as run (see the module's doc): coverage of the 95 % ranges."""
    from metainterface.errors import MetainterfaceError

    rows = []
    for radius in (2e-3, 5e-3, 10e-3):
        for pull in (True, False):
            for noise in (0.01, 0.02, 0.03, 0.04, 0.05):
                for seed in range(per_cell):
                    rng = np.random.default_rng([int(radius * 1e4), pull, int(noise * 100), seed])
                    tau, w = rng.uniform(0.2e6, 0.4e6), rng.uniform(0.02, 0.08)
                    # pull rows down to 70-100 % of pull-off (the last row at it, or short)
                    off = 1.5 * np.pi * w * radius * rng.uniform(0.7, 1.0)
                    fn = np.linspace(-off if pull else 0.0, 60e-3, 25)
                    ff = sphere_friction(fn, tau, w, radius, E)
                    ff = ff * (1 + noise * rng.standard_normal(fn.size))
                    start = time.perf_counter()
                    try:
                        cal = calibrate_sphere(fn, ff, radius=radius, e_star=E)
                    except MetainterfaceError as exc:
                        rows.append((pull, noise, None, None, str(exc)[:60], 0.0))
                        continue
                    ci = cal.interval(0.95)
                    hit_t = ci["tau"][0] <= tau <= ci["tau"][1]
                    hit_w = ci["work"][0] <= w <= ci["work"][1]
                    rows.append((pull, noise, hit_t, hit_w, "", time.perf_counter() - start))
    for label, pick in (
        ("all", lambda r: True),
        ("with pull rows", lambda r: r[0]),
        ("no pull rows", lambda r: not r[0]),
        ("scatter 5 %", lambda r: r[1] == 0.05),
    ):
        sel = [r for r in rows if pick(r)]
        ok = [r for r in sel if r[2] is not None]
        t = sum(r[2] for r in ok) / max(len(ok), 1)
        w = sum(r[3] for r in ok) / max(len(ok), 1)
        both = sum(r[2] and r[3] for r in ok) / max(len(ok), 1)
        print(
            f"{label:15s} {len(sel)} tests, {len(sel) - len(ok)} refused: 95 % range holds "
            f"tau {100 * t:.1f} %, w {100 * w:.1f} %, both {100 * both:.1f} %; "
            f"median {np.median([r[5] for r in ok]):.2g} s a fit",
            flush=True,
        )
    for r in rows:
        if r[2] is None:
            print("  refused:", r[4])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=40, help="made-design tests")
    parser.add_argument("--sphere-seeds", type=int, default=200, help="sphere tests")
    parser.add_argument("--as-run", action="store_true", help="sphere tests as run (issue 52)")
    parser.add_argument("--per-cell", type=int, default=7, help="--as-run: tests per cell")
    args = parser.parse_args()
    if args.as_run:
        as_run(args.per_cell)
        return
    fn = np.linspace(-0.5, 20.0, 25) * 1e-3
    coverage(
        lambda ff: calibrate_sphere(fn, ff, radius=R_SPHERE, e_star=E),
        sphere_friction(fn, TAU, W, R_SPHERE, E),
        args.sphere_seeds,
        "sphere",
    )
    s = CellSettings()
    rng = np.random.default_rng(11)
    h = rng.uniform(0, 0.6, 9) * s.delta_max
    d = mi.Design(gamma=rng.uniform(1.8, 4.0, 9), h=h - h.min(), settings=s)
    g, hh = d.tensors(torch.float64)
    with torch.no_grad():
        model = mi.Independent(adhesion=W / (E * R_ASP))
        p_max = float(model.sweep(g, hh, s, n_delta=2049).p_star[0, -1])
    loads = np.linspace(0.0, 0.95 * p_max, 20) * AREA * E
    coverage(
        lambda ff: calibrate_design(loads, ff, d, e_star=E, area=AREA, radius=R_ASP),
        design_friction(loads, TAU, W, d, e_star=E, area=AREA, radius=R_ASP),
        args.seeds,
        "design",
    )


if __name__ == "__main__":
    main()
