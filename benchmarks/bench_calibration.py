"""Calibration of tau and w (issue 38, item 5): how often the reported 95 % ranges hold the
true values, on synthetic friction tests with 3 % multiplicative noise.

A sphere (R = 5 mm, 25 loads from -0.5 to 20 mN) and a made design (a held-back 9-asperity
cell of 0.5 mm asperities over 4 cm^2, 20 loads from 0 to 95 % of its largest), both on
PDMS (E* = 2.4 MPa, tau = 0.3 MPa, w = 50 mJ/m^2), one noise draw per seed.

    PYTHONPATH=src python benchmarks/bench_calibration.py [--seeds 40] [--sphere-seeds 200]
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


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=40, help="made-design tests")
    parser.add_argument("--sphere-seeds", type=int, default=200, help="sphere tests")
    args = parser.parse_args()
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
