"""A route past the pixel edge: a Hertz asperity's JKR state from a family of bonded discs.

Not used by the package. The JKR-limit BEM (``validation.adhesive_bem.solve_jkr``) decides
its edge point by point, and its error against JKR stops falling past 256 points per cell
side (``bench_adhesive_convergence.py``: lattice trapping, and a contact area counted in
whole points). This benchmark measures a criterion that decides on the whole edge at once,
on one asperity:

- bond discs of grid points {r <= r_j} about the asperity's centre, every distinct radius
  within ``--window`` spacings of a first guess, and solve each twice (``_bonded``, the
  check's own solver): the heights at c = 0 and a uniform unit displacement, so that the
  disc's force at any approach c is F(A, c) = F_0(A) + k(A) c, A its area in points;
- fit F_0 and k by cubics in a = sqrt(A / pi) (the pixels' staircase is noise about them);
- an edge in equilibrium at energy release w has, by Maxwell's relation on the periodic
  cell (F = dU/dc, the stress intensity linear in c on a fixed set),
  K = |dF/da| / sqrt(2 pi a |dk/da| / E*) = K_c = sqrt(2 E* w): solve it for a at each c,
  and report (F, pi a^2) there, between the discs, not on one of them.

The reference is JKR's a(F) (R = 1, E* = 1) written here, not the package's model, and the
periodic images of the cell are left in the BEM (they are physics the check reads, not its
error). Per grid (points per cell side) and approach: the relative error of alpha against
JKR; then the two-grid (Richardson) figure 2 e(M) - e(M / 2), what is left once the
first-order part is taken out.

    PYTHONPATH=src OMP_NUM_THREADS=1 python benchmarks/bench_adhesive_subpixel.py
        [--works 1e-4 5e-4] [--grids 128 256 512]
"""

from __future__ import annotations

import argparse
import math
import time

import numpy as np
import torch

import metainterface as mi
from metainterface.physics import CellSettings
from metainterface.validation.adhesive_bem import (
    PRECONDITIONER_DTYPE,
    _bonded,
    _spectral,
    forward_kernel,
    inverse_kernel,
)
from metainterface.validation.heightmap import height_map

QUICK = "--works 1e-4 --grids 64 --approaches 2"


def jkr_radius(force: float, work: float) -> float:
    """JKR's contact radius under ``force`` (R = 1, E* = 1, work w)."""
    q = 3.0 * math.pi * work
    return ((force + q + math.sqrt(6.0 * math.pi * work * force + q * q)) / (4.0 / 3.0)) ** (
        1.0 / 3.0
    )


def disc_family(grid: int) -> tuple[np.ndarray, np.ndarray, float, float]:
    """The Hertz cell on ``grid``^2: (distance of each point to the centre, distinct
    radii below a quarter of the side, spacing, side)."""
    design = mi.Design(
        gamma=np.array([2.0]), h=np.array([0.0]), settings=CellSettings(n_asperities=1)
    )
    hm = height_map(design, grid)
    centre = design.settings.lattice_centres()[0]
    x = np.arange(grid) * hm.spacing
    dist = np.hypot(x[None, :] - centre[0], x[:, None] - centre[1])
    radii = np.unique(np.round(dist[dist < hm.cell_side / 4], 12))
    return dist, radii, hm.spacing, hm.cell_side


def equilibrium(grid: int, work: float, approaches: np.ndarray, window: float) -> list:
    """(approach, a / dx, error of alpha against JKR, discs solved) per approach."""
    dist, radii, dx, side = disc_family(grid)
    z = torch.as_tensor(-0.5 * dist**2)[None]  # R = 1, tips at 0 (as ``height_map``)
    fwd = _spectral(forward_kernel(grid, side, z.device), torch.complex128)
    stiff = _spectral(inverse_kernel(grid, side, z.device), PRECONDITIONER_DTYPE)
    heights = torch.cat([z, torch.zeros_like(z)])
    shift = torch.tensor([0.0, 1.0], dtype=torch.float64).reshape(2, 1, 1)
    cache: dict[int, tuple[float, float, float]] = {}

    def solve(j: int) -> tuple[float, float, float]:  # (a, F_0, k) of disc j
        if j not in cache:
            disc = torch.as_tensor(dist <= radii[j] + 1e-12)[None].expand(2, -1, -1)
            p, res = _bonded(
                heights, shift, disc, fwd, torch.zeros_like(heights), 1e-12, 5000, stiff
            )
            assert bool((res <= 1e-12).all()), res
            f = p.sum(dim=(1, 2)).numpy() * dx * dx
            cache[j] = (math.sqrt(float(disc[0].sum()) / math.pi) * dx, float(f[0]), float(f[1]))
        return cache[j]

    k_c = math.sqrt(2.0 * work)
    out = []
    for c in approaches:
        # a first guess of the window's centre: the isolated JKR delta(a) (only where to look)
        aa = np.linspace(dx, side / 4, 4000)
        guess = float(aa[np.argmin(np.abs(aa**2 - np.sqrt(2 * math.pi * work * aa) - c))])
        for _ in range(8):  # recentre the window until the root is inside it
            near = np.flatnonzero(np.abs(radii - guess) < window * dx)
            a, f0, k = np.array([solve(int(j)) for j in near]).T
            cf, ck = np.polyfit(a - guess, f0 + k * c, 3), np.polyfit(a - guess, k, 3)
            df, dk = np.polyder(cf), np.polyder(ck)
            s = np.linspace(-window * dx, window * dx, 4001)
            balance = (
                np.abs(np.polyval(df, s))
                - np.sqrt(2 * math.pi * (guess + s) * np.abs(np.polyval(dk, s))) * k_c
            )
            root = np.flatnonzero(np.diff(np.sign(balance)))
            inside = root[np.abs(s[root]) < (window - 1) * dx]
            if inside.size:
                break
            guess += s[np.argmin(np.abs(balance))]  # towards the root
        else:
            out.append((c, math.nan, math.nan, len(cache)))
            continue
        root = inside
        edge = guess + s[root[0]]
        force = float(np.polyval(cf, s[root[0]]))
        error = (edge / jkr_radius(force, work)) ** 2 - 1 if force > 0 else math.nan
        out.append((c, edge / dx, error, len(cache)))
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--works", type=float, nargs="+", default=[1e-4, 5e-4])
    ap.add_argument("--grids", type=int, nargs="+", default=[128, 256, 512])
    ap.add_argument("--approaches", type=int, default=5)
    ap.add_argument("--window", type=float, default=3.0, help="spacings either side")
    args = ap.parse_args()
    for work in args.works:
        # approaches from a step past where JKR's force turns positive to 0.018 R
        a0 = (4.5 * math.pi * work) ** (1 / 3)  # JKR's radius at F = 0
        start = a0 * a0 - math.sqrt(2 * math.pi * work * a0)
        approaches = np.linspace(start + 0.002, 0.018, args.approaches)
        print(f"\nw = {work:g} E* R: alpha against JKR (a / dx at the edge found)")
        print(
            "| approach [R] | "
            + " | ".join(f"{g} pts" for g in args.grids)
            + " | "
            + " | ".join(f"2 e({g}) - e({g // 2})" for g in args.grids[1:])
            + " |"
        )
        print("| ---: " * (2 * len(args.grids)) + "|")
        rows = {}
        for grid in args.grids:
            t0 = time.perf_counter()
            rows[grid] = equilibrium(grid, work, approaches, args.window)
            print(
                f"  {grid} points: {rows[grid][-1][3]} discs in {time.perf_counter() - t0:.1f} s",
                flush=True,
            )
        for i, c in enumerate(approaches):
            e = [rows[g][i][2] for g in args.grids]
            cells = [
                f"{100 * x:+.2f} % ({rows[g][i][1]:.0f})"
                for x, g in zip(e, args.grids, strict=True)
            ]
            rich = [f"{100 * (2 * e[j] - e[j - 1]):+.2f} %" for j in range(1, len(e))]
            print(f"| {c:.4f} | " + " | ".join(cells + rich) + " |")


if __name__ == "__main__":
    main()
