"""Adhesion (issue 38): the adhesive forward models against the adhesive torch BEM.

1. One Hertz asperity (R = 1) with w = 4.2e-5 E* R (PDMS on glass, 50 mJ/m^2, E* = 2.4 MPa,
   R = 0.5 mm) in the JKR limit (Pohrt-Popov criterion) on grids 128 and 256: the contact
   area at each compressive force against the JKR closed form a(P), loading and unloading.
2. A 9-asperity design (the packaged example) with the same w: the BEM's load-controlled
   states (force at its running maximum) against Independent(adhesion=w) and
   Interacting(adhesion=w) at the same P*; and what adhesion changes in the model's curve.

    PYTHONPATH=src python benchmarks/bench_adhesion.py [--grids 128 256] [--design-grid 288]
"""

from __future__ import annotations

import argparse
import math
import time
from importlib.resources import files

import numpy as np
import torch

import metainterface as mi
from metainterface.physics import CellSettings, Design
from metainterface.validation.adhesive_path import jkr_path
from metainterface.validation.heightmap import height_map

W = 4.2e-5


def jkr_sphere_radius(force: float, w: float) -> float:
    q = 3 * math.pi * w
    return ((force + q + math.sqrt(6 * math.pi * w * force + q * q)) / (4 / 3)) ** (1 / 3)


def hertz(grid: int) -> None:
    design = Design(gamma=np.array([2.0]), h=np.array([0.0]), settings=CellSettings(n_asperities=1))
    hm = height_map(design, grid)
    side = hm.cell_side
    start = time.perf_counter()
    path = jkr_path(
        hm.heights, side, W, np.linspace(0, 0.02, 9)[1:], unload=np.linspace(0.02, 0.002, 7)[1:]
    )
    seconds = time.perf_counter() - start
    errs: dict[str, list[float]] = {"load": [], "unload": []}
    for i in range(path.p_star.size):
        force = path.p_star[i] * side**2
        if force <= 0:
            continue
        a = jkr_sphere_radius(force, W)
        err = path.alpha[i] * side**2 / (math.pi * a * a) - 1
        kind = "load" if path.loading[i] else "unload"
        errs[kind].append(abs(err))
        # the edge's offset from the JKR radius in grid spacings: an O(dx) error falls as 1/M
        a_bem = side * math.sqrt(path.alpha[i] / math.pi)
        print(
            f"  {kind:6s} Delta={path.approach[i]:.4f} F/(E* R^2)={force:.3e} a/dx="
            f"{a_bem / hm.spacing:5.1f} alpha err {err:+.4f} (a - a_JKR) / dx "
            f"{(a_bem - a) / hm.spacing:+.3f}"
        )
    print(
        f"grid {grid}: Hertz asperity, JKR limit: max |alpha err| loading "
        f"{max(errs['load']):.4f}, unloading {max(errs['unload']):.4f} ({seconds:.1f} s)"
    )


def cell(grid: int) -> None:
    design = Design.load(files("metainterface") / "examples" / "example_design.json")
    s = design.settings
    hm = height_map(design, grid)
    start = time.perf_counter()
    path = jkr_path(hm.heights, hm.cell_side, W, np.linspace(0, s.delta_max, 17)[1:])
    seconds = time.perf_counter() - start
    gamma, h = design.tensors()
    loads = torch.as_tensor(path.p_star[path.on_branch])[None]
    bem = path.alpha[path.on_branch]
    for model in (mi.Independent(adhesion=W), mi.Interacting(adhesion=W)):
        with torch.no_grad():
            alpha = model.alpha_at_loads(gamma, h, s, loads)[0].numpy()
        err = alpha / bem - 1
        print(
            f"grid {grid}: example design, {model.label}: alpha vs BEM at {bem.size} loads: "
            f"max |err| {np.abs(err).max():.4f}, rms {np.sqrt((err**2).mean()):.4f}"
        )
    plain = mi.Independent().alpha_at_loads(gamma, h, s, loads)[0].numpy()
    with torch.no_grad():
        adh = mi.Independent(adhesion=W).alpha_at_loads(gamma, h, s, loads)[0].numpy()
    print(
        f"  adhesion raises alpha by x{adh[0] / plain[0]:.2f} at the lowest load, "
        f"{100 * (adh[-1] / plain[-1] - 1):+.0f} % at the largest; pull-off P*_off = "
        f"{mi.Independent(adhesion=W).design_pull_off(design):.3e} ({seconds:.1f} s BEM)"
    )


# Quick mode (`python benchmarks/run.py run --quick`, CI): seconds, same code paths.
QUICK = "--grids 48 --design-grid 48"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--grids", type=int, nargs="*", default=[128, 256])
    parser.add_argument("--design-grid", type=int, default=288)
    args = parser.parse_args()
    torch.set_num_threads(1)
    for grid in args.grids:
        hertz(grid)
    if args.design_grid:
        cell(args.design_grid)


if __name__ == "__main__":
    main()
