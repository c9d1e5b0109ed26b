"""Does the adhesive check's error fall with its grid, and does its estimate hold? (issue 52)

A Hertz asperity (gamma = 2, one per cell) under a rising force in the JKR-limit BEM, checked
as a design's check runs (``verify.adhesive.bounded_check`` on a given grid M and M / 2, 10
loads), against the JKR closed form written here (not the package's model): a(F) from
F = 4 a^3 / 3 - sqrt(8 pi w a^3), R = 1, E* = 1. Per work of adhesion w [E* R] and grid
(points per cell side): the check's own error estimate, its true error against JKR (the
relative L2 error of alpha over the check's states, as the check measures it), whether the
estimate holds it, and the mean signed error over the lowest third of the loads, where the
contact's stress intensity sets alpha (a lagging loading edge reads low there).

    PYTHONPATH=src OMP_NUM_THREADS=1 python benchmarks/bench_adhesive_convergence.py
        [--works 2e-5 4.2e-5 1e-4 2e-4 5e-4] [--grids 64 128 256 512] [--classes 256 512]

``--classes GRID ...`` prints instead why the criterion pins an edge: a bonded flat punch of
radius L / 10 on each grid (a pull, no criterion), its edge points' tension and the points
beside it's gap, grouped by how many of their 4- and diagonal neighbours are in contact, as
factors of Kendall's K_I (tension |p| sqrt(dx) / K, gap g / (K sqrt(dx)), a from the pixel
count); and the same for single points added beside the edge (a bump, bonded). The
criterion uses one factor for every edge point (c_e) and one for every point beside it (c_g).

The package refuses an adhesive check or validation finer than
``validation.adhesive_path.FINEST`` points per cell side; this benchmark goes past it to
show why.
"""

from __future__ import annotations

import argparse
import math
import time

import numpy as np

import metainterface as mi
from metainterface.physics import CellSettings
from metainterface.validation.adhesive_path import FINEST
from metainterface.validation.heightmap import height_map
from metainterface.verify.adhesive import bounded_check

# Quick mode (`python benchmarks/run.py run --quick`, CI): seconds, same code paths.
QUICK = "--works 4.2e-5 --grids 64"


def jkr_radius(force: np.ndarray | float, work: float) -> np.ndarray | float:
    """JKR's contact radius under ``force`` >= 0 (R = 1, E* = 1, work of adhesion w):
    F = 4 a^3 / 3 - sqrt(8 pi w a^3) solved for a."""
    q = 3.0 * math.pi * work
    return ((force + q + np.sqrt(6.0 * math.pi * work * force + q * q)) / (4.0 / 3.0)) ** (
        1.0 / 3.0
    )


def jkr_target(work: float) -> tuple[mi.Design, mi.Target]:
    """The Hertz cell and its JKR loading curve (63 loads up to the model's top)."""
    design = mi.Design(
        gamma=np.array([2.0]), h=np.array([0.0]), settings=CellSettings(n_asperities=1)
    )
    side = height_map(design, 16).cell_side
    top = float(mi.Independent(adhesion=work).model_curve(design).p_star_max)
    p = np.linspace(0.0, top, 64)
    a = jkr_radius(p * side**2, work)
    return design, mi.Target(p_star=p, alpha=math.pi * a * a / side**2, name="jkr")


def _counts(mask: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(M, M) each point's count of 4-neighbours and of diagonal neighbours in ``mask``."""
    four = sum(np.roll(mask, s, axis=a) for a in (0, 1) for s in (1, -1))
    diag = sum(np.roll(np.roll(mask, s, 0), t, 1) for s in (1, -1) for t in (1, -1))
    return four.astype(int), diag.astype(int)


def edge_classes(grid: int, radius: float = 0.1) -> None:
    """The bonded punch's edge factors by neighbour class (see the module's doc)."""
    import torch

    from metainterface.validation.adhesive_bem import _apply, _bonded, _spectral, forward_kernel
    from metainterface.validation.adhesive_edge import _kendall_k, _punch

    _, disc, dx = _punch(grid, radius)  # the calibration's own punch and Kendall's K_I
    punch = disc[0].numpy()
    four, diag = _counts(punch)
    beside = np.flatnonzero((~punch & (four > 0)).ravel())
    bumps = punch.copy()
    bumps.flat[beside[:: max(1, beside.size // 40)]] = True  # ~40 bumps around the edge
    fwd = forward_kernel(grid, 1.0, torch.device("cpu"))
    spectral = _spectral(fwd, torch.complex128)
    pull = torch.full((1, 1, 1), -1e-3, dtype=torch.float64)
    flat = torch.zeros((1, grid, grid), dtype=torch.float64)
    print(f"grid {grid}, punch radius {radius * grid:.0f} points:")
    for name, mask in (("punch", punch), ("with bumps", bumps)):
        c = torch.as_tensor(mask)[None]
        p, _ = _bonded(flat, pull, c, fwd, torch.zeros_like(flat), 1e-12, 20000)
        gap = (_apply(p, spectral) - pull)[0].numpy()
        k = _kendall_k(p, float(punch.sum()), dx)
        tension = p[0].abs().numpy() * math.sqrt(dx) / k
        opening = gap / (k * math.sqrt(dx))
        four, diag = _counts(mask)
        sets = (("tension", mask & (four < 4), tension), ("gap", ~mask & (four > 0), opening))
        if name != "punch":
            new = bumps & ~punch
            sets = (("bump tension", new, tension),)
        for what, where, value in sets:
            cells = sorted(set(zip(four[where].tolist(), diag[where].tolist(), strict=True)))
            text = ", ".join(
                f"({a},{b}) {value[where & (four == a) & (diag == b)].mean():.3f}"
                f" +- {value[where & (four == a) & (diag == b)].std():.3f}"
                for a, b in cells
            )
            print(f"  {name}: {what} by (4-, diagonal neighbours): {text}", flush=True)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--works", type=float, nargs="+", default=[2e-5, 4.2e-5, 1e-4, 2e-4, 5e-4])
    ap.add_argument("--grids", type=int, nargs="+", default=[64, 128, 256, 512])
    ap.add_argument("--loads", type=int, default=10)
    ap.add_argument("--classes", type=int, nargs="+", default=None, metavar="GRID")
    args = ap.parse_args()
    if args.classes:
        for grid in args.classes:
            edge_classes(grid)
        return
    print(f"the package's finest adhesive check: {FINEST} points per cell side")
    print(
        "| w [E* R] | grid | check's estimate | true error (vs JKR) | held "
        "| low-load mean error | seconds |"
    )
    print("| ---: | ---: | ---: | ---: | --- | ---: | ---: |")
    held = {True: [0, 0], False: [0, 0]}  # within FINEST or not: [held, cases]
    for work in args.works:
        design, target = jkr_target(work)
        model = mi.Independent(adhesion=work)
        for grid in args.grids:
            start = time.perf_counter()
            try:
                b = bounded_check(
                    design, target, model, grid=grid, loads=args.loads, max_error=0.02
                )
            except mi.MetainterfaceError as exc:
                print(f"| {work:g} | {grid} | - | - | - | {exc} | |")
                continue
            s = b.solved
            t = np.interp(s.p_star, target.p_star, target.alpha)
            true = float(np.linalg.norm(s.alpha_bem - t) / np.linalg.norm(t))
            low = s.p_star <= s.p_star[0] + (s.p_star[-1] - s.p_star[0]) / 3
            signed = float(np.mean((s.alpha_bem[low] - t[low]) / t[low]))
            ok = true <= b.accuracy
            tally = held[grid <= FINEST]
            tally[0] += ok
            tally[1] += 1
            print(
                f"| {work:g} | {grid} | {100 * b.accuracy:.2f} % | {100 * true:.2f} % "
                f"| {'yes' if ok else 'NO'} | {100 * signed:+.2f} % "
                f"| {time.perf_counter() - start:.0f} |",
                flush=True,
            )
    for within, (ok, n) in held.items():
        if n:
            side = "up to" if within else "above"
            print(f"\nthe estimate holds the true error on {ok} of {n} checks {side} {FINEST}")


if __name__ == "__main__":
    main()
