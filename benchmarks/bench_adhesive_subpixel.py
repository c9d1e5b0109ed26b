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

``--cell APPROACH --grids 384 [--discs 60 150] [--seeds 0 1 2]`` tries it on the package's
nine-asperity example cell (w the first of ``--works``): one family whose nine radii vary
at random together, each asperity's region force regressed on its own radius (a cubic) and
on the others' (linear), so that the edges are found together. It prints P* and alpha per
family size and seed (their spread is the regression's noise), beside the point-by-point
BEM's state at the same approach, and the family's seconds.

``--reciprocal APPROACH ... --grids 192 384 768`` finds each of the example cell's edges from
a family of its own asperity alone, the others' pressures held as loads, which reciprocity
makes independent of the approach and of those loads (``reciprocal_state``): P* and alpha
per grid, and alpha extrapolated from each grid and the one before (at a fixed approach).

``--path SAMPLES --grids 192 384`` loads the example cell along the check's own approaches
(``adhesive_path.approaches``) with it, each asperity joining where its tip's gap falls
below 0 and each disc alone solved once for the whole path (``path_states``): per state P*
and alpha per grid, the extrapolated alpha, the point-by-point path's state, and the seconds
of both. ``--stride N`` fits every N-th of each asperity's distinct radii only; ``--busy N``
runs the path beside N CPU-bound processes.

``--ring THICKNESS ...`` measures the cheapest variant on the Hertz asperity: no fit, the
exact differences between a disc and the disc grown by one ring (two solves a state), at
disc radii 0.07-0.2 R; the mean error of alpha against JKR and its spread over the states.
"""

from __future__ import annotations

import argparse
import functools
import math
import time

import numpy as np
import torch

import metainterface as mi
from bench_adhesive_convergence import jkr_radius  # JKR's a(F), written there
from metainterface.physics import CellSettings
from metainterface.physics.sneddon import shape_constant
from metainterface.validation.adhesive_bem import (
    PRECONDITIONER_DTYPE,
    _bonded,
    _spectral,
    forward_kernel,
    inverse_kernel,
)
from metainterface.validation.heightmap import height_map

# Quick mode (CI): the --path mode on a coarse grid, seconds: it goes through the most of
# the package (the check's approaches, ``_bonded`` on windows and on the cell, ``jkr_path``);
# the other modes are minutes long and share its pieces.
QUICK = "--path 3 --grids 96"


def cell_kernels(grid: int, side: float) -> tuple[torch.Tensor, torch.Tensor]:
    """The periodic cell's compliance and preconditioner, as ``_bonded`` takes them."""
    device = torch.device("cpu")
    return (
        _spectral(forward_kernel(grid, side, device), torch.complex128),
        _spectral(inverse_kernel(grid, side, device), PRECONDITIONER_DTYPE),
    )


def pair_solver(heights: np.ndarray, fwd: torch.Tensor, stiff: torch.Tensor, tolerance: float):
    """``solve(sets, start=None)``: the points ``sets`` (M, M) bool of the surface
    ``heights`` (M, M) bonded (``_bonded``, compliance ``fwd``, preconditioner ``stiff``),
    at c = 0 and for a unit approach, so that the pressure at any approach c is
    p[0] + c p[1]. Returns (p (2, M, M), residual (2,)); ``start`` (2, M, M) a warm start."""
    z = torch.as_tensor(heights)
    pair = torch.stack([z, torch.zeros_like(z)])
    shift = torch.tensor([0.0, 1.0], dtype=torch.float64).reshape(2, 1, 1)

    def solve(sets: np.ndarray, start: torch.Tensor | None = None):
        mask = torch.as_tensor(sets)[None].expand(2, -1, -1)
        first = torch.zeros_like(pair) if start is None else start * mask
        return _bonded(pair, shift, mask, fwd, first, tolerance, 5000, stiff)

    return solve


def disc_family(grid: int):
    """The Hertz cell on ``grid``^2: (distance of each point to the centre, distinct
    radii below a quarter of the side, spacing, side, ``pair_solver`` of its heights)."""
    design = mi.Design(
        gamma=np.array([2.0]), h=np.array([0.0]), settings=CellSettings(n_asperities=1)
    )
    hm = height_map(design, grid)
    centre = design.settings.lattice_centres()[0]
    x = np.arange(grid) * hm.spacing
    dist = np.hypot(x[None, :] - centre[0], x[:, None] - centre[1])
    radii = np.unique(np.round(dist[dist < hm.cell_side / 4], 12))
    z = -0.5 * dist**2  # R = 1, tips at 0 (as ``height_map``)
    solve = pair_solver(z, *cell_kernels(grid, hm.cell_side), tolerance=1e-12)
    return dist, radii, hm.spacing, hm.cell_side, solve


def equilibrium(grid: int, work: float, approaches: np.ndarray, window: float) -> list:
    """(approach, a / dx, error of alpha against JKR, discs solved) per approach."""
    dist, radii, dx, side, bonded = disc_family(grid)
    cache: dict[int, tuple[float, float, float]] = {}

    def solve(j: int) -> tuple[float, float, float]:  # (a, F_0, k) of disc j
        if j not in cache:
            disc = dist <= radii[j] + 1e-12
            p, res = bonded(disc)
            assert bool((res <= 1e-12).all()), res
            f = p.sum(dim=(1, 2)).numpy() * dx * dx
            cache[j] = (math.sqrt(float(disc.sum()) / math.pi) * dx, float(f[0]), float(f[1]))
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


def ring_states(grid: int, work: float, thickness: float) -> np.ndarray:
    """The one-ring variant: a disc of radius r and the disc grown by a ring ``thickness``
    spacings thick, their differences dF_0, dk, dA (exact: no fit), give the approach c*
    at which |dF_0 + c dk| = sqrt(dA |dk|) K_c, and the state (F, pi a^2) there with a at
    the ring's middle. Returns (a / dx, error of alpha against JKR) (S, 2) for discs of
    radius 0.07-0.2 R in steps of 0.37 dx."""
    dist, _, dx, _, bonded = disc_family(grid)

    def solve(r: float) -> tuple[int, float, float]:
        disc = dist <= r + 1e-12
        p, _ = bonded(disc)
        f = p.sum(dim=(1, 2)).numpy() * dx * dx
        return int(disc.sum()), float(f[0]), float(f[1])

    out = []
    for r in np.arange(0.07, 0.2, 0.37 * dx):
        (n0, f0, k0), (n1, f1, k1) = solve(r), solve(r + thickness * dx)
        if n1 == n0:
            continue
        area, d_f, d_k = (n1 - n0) * dx * dx, f1 - f0, k1 - k0
        c = (-math.sqrt(2 * work) * math.sqrt(area * abs(d_k)) - d_f) / d_k
        a = math.sqrt((n0 + n1) / 2 / math.pi) * dx
        force = (f0 + f1) / 2 + c * (k0 + k1) / 2
        if force > 0:
            out.append((a / dx, (a / jkr_radius(force, work)) ** 2 - 1))
    return np.array(out)


@functools.cache
def _example_cell(grid: int):
    """The package's nine-asperity example cell on ``grid``^2: (design, height map, each
    point's offsets (x, y) from its asperity's centre and distance to it). Made once a grid:
    callers only read it."""
    import json
    from pathlib import Path

    spec = json.loads((Path(mi.__file__).parent / "examples" / "example_design.json").read_text())
    design = mi.Design(
        gamma=np.array(spec["gamma"]), h=np.array(spec["h"]), settings=CellSettings()
    )
    hm = height_map(design, grid)
    centres = design.settings.lattice_centres()[hm.owner]
    x = np.arange(grid) * hm.spacing
    dx_, dy_ = x[None, :] - centres[..., 0], x[:, None] - centres[..., 1]
    return design, hm, dx_, dy_, np.hypot(dx_, dy_)


def cell_state(
    grid: int, work: float, c: float, discs: int, seed: int, window: float, order: str
) -> dict:
    """The nine-asperity example cell at approach ``c`` by a family of ``discs`` disc sets
    whose nine radii vary at random (``seed``) within ``window`` spacings of the
    point-by-point BEM's state, each region's force F_l regressed on its own radius (a
    cubic) and the others' (linear), and each edge put where Maxwell's relation holds with
    the total force. Returns P* and alpha of both, and the family's seconds."""
    from metainterface.validation.adhesive_bem import solve_jkr

    design, hm, _, _, dist = _example_cell(grid)
    side, dx, own = hm.cell_side, hm.spacing, hm.owner
    z = torch.as_tensor(hm.heights)[None]
    pixel = solve_jkr(z, side, torch.tensor([-float(z.mean()) - c]), work)
    n = np.bincount(own[pixel.contact[0].numpy()], minlength=design.gamma.size)
    touching = np.flatnonzero(n > 0)
    rho = np.sqrt(n / math.pi) * dx
    bonded = pair_solver(hm.heights, *cell_kernels(grid, side), tolerance=1e-12)
    rng = np.random.default_rng(seed)
    t0 = time.perf_counter()
    radius, force0, stiffness = [], [], []
    p = None
    # "shells": each asperity's distinct radii in the window, in an order of its own, so
    # every radius is drawn (as the single asperity's family) and the nine are unrelated
    shells = [
        np.unique(dist[(own == k) & (np.abs(dist - rho[k]) < window * dx)]) for k in range(n.size)
    ]
    # (drawn only for that order: the random order's draws are the first the seed gives)
    orders = [rng.permutation(max(len(s), 1)) for s in shells] if order == "shells" else []
    for j in range(discs):
        if order == "shells":
            r = np.array(
                [
                    s[o[j % len(o)]] if len(s) and n[k] else -1.0
                    for k, (s, o) in enumerate(zip(shells, orders, strict=True))
                ]
            )
        else:
            r = rho + rng.uniform(-window, window, n.size) * dx
        r = np.where(n > 0, np.maximum(r, dx), -1)
        sets = dist <= r[own] + 1e-12
        p, _ = bonded(sets, p)
        radius.append(np.sqrt(np.bincount(own[sets], minlength=n.size) / math.pi) * dx - rho)
        per = [
            np.bincount(own.ravel(), weights=p[i].numpy().ravel(), minlength=n.size) for i in (0, 1)
        ]
        force0.append(per[0] * dx * dx)
        stiffness.append(per[1] * dx * dx)
    xs = np.array(radius)

    def fit(y: np.ndarray) -> dict:  # region j: (own cubic, {k: linear in x_k})
        out = {}
        for j in touching:
            rest = [k for k in touching if k != j]
            a = np.column_stack([xs[:, j] ** q for q in range(4)] + [xs[:, k] for k in rest])
            b = np.linalg.lstsq(a, np.array(y)[:, j], rcond=None)[0]
            out[j] = (b[:4], dict(zip(rest, b[4:], strict=True)))
        return out

    f0, kk = fit(force0), fit(stiffness)

    def slope(cf: dict, k: int, v: np.ndarray) -> np.ndarray:  # d(total)/dx_k
        own_part = cf[k][0][1] + 2 * cf[k][0][2] * v + 3 * cf[k][0][3] * v * v
        return own_part + sum(cf[j][1][k] for j in touching if j != k)

    edge = np.zeros(n.size)
    v = np.linspace(-(window - 1) * dx, (window - 1) * dx, 2001)
    for k in touching:
        balance = np.abs(slope(f0, k, v) + c * slope(kk, k, v)) - np.sqrt(
            2 * math.pi * (rho[k] + v) * np.abs(slope(kk, k, v))
        ) * math.sqrt(2 * work)
        root = np.flatnonzero(np.diff(np.sign(balance)))
        edge[k] = v[root[0]] if root.size else math.nan
    total = 0.0
    for cf, weight in ((f0, 1.0), (kk, c)):
        for j in touching:
            b, cross = cf[j]
            total += weight * (
                np.polyval(b[::-1], edge[j]) + sum(g * edge[k] for k, g in cross.items())
            )
    alpha = float(np.sum(math.pi * (rho + edge)[touching] ** 2)) / side**2
    return {
        "p_star": total / side**2,
        "alpha": alpha,
        "seconds": time.perf_counter() - t0,
        "pixel": (float(pixel.p_star[0]), float(pixel.alpha[0])),
        "touching": touching.size,
    }


class ReciprocalCell:
    """The example cell on ``grid``^2 with each edge from its own asperity's family.

    Disc k bonded under the other asperities' displacement u_ext carries, by reciprocity,
    F_k(a) = F_0k(a) + c k_k(a) - sum(p1_k(a) u_ext) (p1_k(a) the disc's pressure under a
    unit approach); with u_ext fitted by u_0 + u_2 r^2 (+ a tilt, which a centred disc does
    not feel) over the disc, F_k(a) = F_0k(a) + (c - u_0) k_k(a) - u_2 M2_k(a),
    M2_k = sum(p1_k r^2). F_0k, k_k and M2_k, disc k alone in the periodic cell, depend on
    neither c nor u_ext: each disc is solved once (``alone``) for every state that needs it.
    ``settle`` puts each edge where Maxwell's relation holds for its F_k (cubic fits over
    the distinct radii within ``window`` spacings), iterating the radii and u_ext with
    coupled solves of the touching discs until the edges move by less than 0.05 spacing.

    A disc alone lies within ``reach`` points of its centre (one for all, or (N,) one an
    asperity), so its solves run on a window of 2m x 2m points, m = 2 reach + 2 (at most the
    lattice square + 2), the cell's periodic
    kernel cut to offsets below m and zero-padded: a linear convolution, exact for every pair
    of the window's points (``window_error`` checks it against the whole cell).
    """

    def __init__(
        self, grid: int, work: float, window: float, reach: int | np.ndarray, stride: int = 1
    ) -> None:
        self.design, self.hm, self.off_x, self.off_y, self.dist = _example_cell(grid)
        self.grid, self.work, self.window = grid, work, window
        # every stride-th of each asperity's distinct radii (counted from its centre) is fitted
        self.shells = [
            np.unique(np.round(self.dist[self.hm.owner == k], 12))[::stride]
            for k in range(self.design.gamma.size)
        ]
        self.side, self.dx, self.own = self.hm.cell_side, self.hm.spacing, self.hm.owner
        self.fwd, stiff = cell_kernels(grid, self.side)
        self.bonded = pair_solver(self.hm.heights, self.fwd, stiff, tolerance=1e-12)
        side_points = grid // self.design.settings.n_side
        reaches = np.broadcast_to(np.asarray(reach), self.design.gamma.shape)
        self.m = [min(side_points, 2 * int(r)) + 2 for r in reaches]  # each disc's window
        self.kernel = torch.fft.irfft2(
            forward_kernel(grid, self.side, torch.device("cpu"))[0].to(torch.complex128),
            s=(grid, grid),
        )
        self.kernels: dict[int, tuple[torch.Tensor, torch.Tensor]] = {}
        self.windows: dict[int, tuple] = {}
        self.cache: dict[tuple[int, float], tuple[float, float, float, float]] = {}

    def _kernels(self, m: int) -> tuple[torch.Tensor, torch.Tensor]:
        """The window of 2m x 2m points' compliance (the cell's kernel cut to offsets below
        m, zero-padded) and preconditioner, both as ``_bonded`` takes them."""
        if m not in self.kernels:
            grid = self.grid
            cut = torch.zeros(2 * m, 2 * m, dtype=torch.float64)
            near, src = np.r_[0:m, m + 1 : 2 * m], np.r_[0:m, grid - m + 1 : grid]
            cut[np.ix_(near, near)] = self.kernel[np.ix_(src, src)]
            self.kernels[m] = (
                _spectral(torch.fft.rfft2(cut)[None], torch.complex128),
                _spectral(inverse_kernel(2 * m, 2 * m * self.dx, cut.device), PRECONDITIONER_DTYPE),
            )
        return self.kernels[m]

    def _window(self, k: int) -> tuple:
        """Disc k's window: distances to its centre (inf off it), its own points, and the
        ``pair_solver`` of its heights on the window's kernels."""
        if k not in self.windows:
            m, dist, own = self.m[k], self.dist, self.own
            cy, cx = np.unravel_index(np.argmin(np.where(own == k, dist, np.inf)), dist.shape)
            rows, cols = np.ix_(
                (np.arange(m) + cy - m // 2) % self.grid, (np.arange(m) + cx - m // 2) % self.grid
            )
            zw, dw = np.zeros((2 * m, 2 * m)), np.full((2 * m, 2 * m), np.inf)
            mine = np.zeros((2 * m, 2 * m), dtype=bool)
            zw[:m, :m], dw[:m, :m] = self.hm.heights[rows, cols], dist[rows, cols]
            mine[:m, :m] = own[rows, cols] == k
            # to 1e-9: the fits read the sums to ~1e-6 (a fifth fewer steps than 1e-12)
            solve = pair_solver(zw, *self._kernels(m), tolerance=1e-9)
            self.windows[k] = (dw, mine, solve)
        return self.windows[k]

    def sums(self, k: int, r: float) -> tuple[float, float, float, float]:
        """Disc k of radius r alone, on its window: (a, F_0k, k_k, M2_k)."""
        dw, mine, solve = self._window(k)
        dx = self.dx
        disc = mine & (dw <= r + 1e-12)
        p, _ = solve(disc)
        unit = p[1].numpy()
        return (
            math.sqrt(float(disc.sum()) / math.pi) * dx,
            float(p[0].sum()) * dx * dx,
            float(unit.sum()) * dx * dx,
            float((unit * np.where(mine, dw, 0.0) ** 2).sum()) * dx * dx,
        )

    def alone(self, k: int, r: float) -> tuple[float, float, float, float]:
        key = (k, round(r / self.dx, 9))
        if key not in self.cache:
            self.cache[key] = self.sums(k, r)
        return self.cache[key]

    def window_error(self, k: int, r: float) -> float:
        """Largest relative difference of ``sums``' three sums against the whole cell."""
        own, dist, dx = self.own, self.dist, self.dx
        p, _ = self.bonded((own == k) & (dist <= r + 1e-12))
        unit = p[1].numpy()
        whole = np.array([float(p[0].sum()), float(unit.sum()), float((unit * dist**2).sum())])
        return float(np.max(np.abs(np.array(self.sums(k, r)[1:]) / (whole * dx * dx) - 1)))

    def coupled(self, c: float, rho: np.ndarray, touching: np.ndarray) -> torch.Tensor:
        """(M, M) the pressure of the touching discs (radii ``rho``) bonded at approach c."""
        own, dist = self.own, self.dist
        p, _ = self.bonded(np.isin(own, touching) & (dist <= rho[own] + 1e-12))
        return p[0] + c * p[1]

    def settle(self, c: float, rho: np.ndarray, touching: np.ndarray) -> tuple[np.ndarray, float]:
        """The edges (N,) at approach c from the radii ``rho``, and the force there."""
        from metainterface.validation.adhesive_bem import _apply

        own, dist, dx, window = self.own, self.dist, self.dx, self.window
        k_c = math.sqrt(2.0 * self.work)
        s = np.linspace(-(window - 1) * dx, (window - 1) * dx, 4001)
        rho = rho.copy()
        force = 0.0
        for _ in range(8):
            pressure = self.coupled(c, rho, touching)
            others = torch.stack([pressure * torch.as_tensor(own != k) for k in touching])
            u_ext = _apply(others, self.fwd).numpy()
            edge, force = rho.copy(), 0.0
            for i, k in enumerate(touching):
                near = (own == k) & (dist <= rho[k] + window * dx)
                basis = np.column_stack(
                    [np.ones(near.sum()), dist[near] ** 2, self.off_x[near], self.off_y[near]]
                )
                u0, u2 = np.linalg.lstsq(basis, u_ext[i][near], rcond=None)[0][:2]
                centre = max(rho[k], window * dx)
                for _ in range(24):  # move the window until the edge is inside it
                    shells = self.shells[k]
                    radii = shells[np.abs(shells - centre) < window * dx]
                    a, f0, kk, m2 = np.array([self.alone(int(k), r) for r in radii]).T
                    cf = np.polyfit(a - centre, f0 + (c - u0) * kk - u2 * m2, 3)
                    ck = np.polyfit(a - centre, kk, 3)
                    # K_k - K_c in force units: K_k from -dF/da (a tensile edge: the force
                    # falls as the disc grows); rises through 0 at the stable edge
                    balance = (
                        -np.polyval(np.polyder(cf), s)
                        - np.sqrt(
                            2
                            * math.pi
                            * np.maximum(centre + s, 0.0)
                            * np.abs(np.polyval(np.polyder(ck), s))
                        )
                        * k_c
                    )
                    up = np.flatnonzero((balance[:-1] < 0) & (balance[1:] >= 0))
                    if up.size:
                        root = up[np.argmin(np.abs(s[up]))]
                        break
                    step = (window - 1) * dx
                    centre = centre + step if balance[-1] < 0 else max(centre - step, window * dx)
                else:
                    raise RuntimeError(f"no edge found for asperity {k} at approach {c:g}")
                at = s[root]
                edge[k] = centre + at
                force += np.polyval(cf, at)
            moved = float(np.abs(edge - rho)[touching].max()) / dx
            rho = edge
            if moved < 0.05:
                break
        return rho, force


def reciprocal_state(grid: int, work: float, c: float, window: float) -> dict:
    """The example cell at approach ``c`` (``ReciprocalCell``), from the point-by-point
    BEM's state there: P*, alpha, discs solved, seconds, that state, and the window's check."""
    from metainterface.validation.adhesive_bem import solve_jkr

    design, hm, _, _, _ = _example_cell(grid)
    z = torch.as_tensor(hm.heights)[None]
    t0 = time.perf_counter()
    pixel = solve_jkr(z, hm.cell_side, torch.tensor([-float(z.mean()) - c]), work)
    n = np.bincount(hm.owner[pixel.contact[0].numpy()], minlength=design.gamma.size)
    touching = np.flatnonzero(n > 0)
    rho = np.sqrt(n / math.pi) * hm.spacing
    reach = math.ceil(float(rho[touching].max()) / hm.spacing + window + 3)
    cell = ReciprocalCell(grid, work, window, reach)
    rho, force = cell.settle(c, rho, touching)
    seconds = time.perf_counter() - t0
    k0 = int(touching[0])
    return {
        "p_star": force / hm.cell_side**2,
        "alpha": float(np.sum(math.pi * rho[touching] ** 2)) / hm.cell_side**2,
        "discs": len(cell.cache),
        "seconds": seconds,
        "pixel": (float(pixel.p_star[0]), float(pixel.alpha[0])),
        "window_error": cell.window_error(k0, rho[k0]),
    }


def path_states(grid: int, work: float, samples: int, window: float, stride: int = 1) -> dict:
    """The example cell loaded along the check's own approaches (``adhesive_path.approaches``,
    ``samples`` of them up to the model's top load), each state settled by ``ReciprocalCell``
    from the one before; an asperity joins where its tip's gap under the settled state is
    below 0 (its edge then found from 3 spacings up). Returns per state (approach, P*, alpha,
    touching), the discs solved, the seconds, and the point-by-point path's P* and alpha."""
    from metainterface.validation.adhesive_bem import _apply
    from metainterface.validation.adhesive_path import approaches, jkr_path

    design, hm, _, _, dist = _example_cell(grid)
    model = mi.Independent(adhesion=work)
    deltas = approaches(design, model, float(model.model_curve(design).p_star_max), samples)
    dx, own, n = hm.spacing, hm.owner, design.gamma.size
    tips = np.array([np.argmin(np.where(own == k, dist, np.inf)) for k in range(n)])
    z_tip = hm.heights.reshape(-1)[tips]
    # the windows reach past the largest rigid-overlap radius at the last approach, by half
    # again (adhesion holds the contact wider) and the fit's window
    overlap = np.maximum(deltas[-1] + z_tip, 0.0)
    shape = shape_constant(torch.as_tensor(design.gamma), design.settings.radius).numpy()
    radius = (overlap / shape) ** (1.0 / design.gamma)  # z = -(h + c_k r^gamma)
    reach = np.ceil(1.5 * radius / dx + window + 3).astype(int)  # points, per asperity
    t0 = time.perf_counter()
    cell = ReciprocalCell(grid, work, window, reach, stride)
    rho = np.zeros(n)
    touching = np.zeros(0, dtype=int)
    states = []
    for c in deltas:
        force = 0.0
        for _ in range(n + 1):
            if touching.size:
                rho, force = cell.settle(float(c), rho, touching)
                u = _apply(cell.coupled(float(c), rho, touching)[None], cell.fwd)[0].numpy()
                gap = u.reshape(-1)[tips] - z_tip - c
            else:
                gap = -z_tip - c
            new = np.setdiff1d(np.flatnonzero(gap < 0), touching)
            if not new.size:
                break
            rho[new] = window * dx
            touching = np.union1d(touching, new)
        alpha = float(np.sum(math.pi * rho[touching] ** 2)) / hm.cell_side**2
        states.append((float(c), force / hm.cell_side**2, alpha, touching.size))
    seconds = time.perf_counter() - t0
    t1 = time.perf_counter()
    pixel = jkr_path(hm.heights, hm.cell_side, work, deltas)
    return {
        "states": states,
        "discs": len(cell.cache),
        "seconds": seconds,
        "pixel": (pixel.p_star, pixel.alpha),
        "pixel_seconds": time.perf_counter() - t1,
    }


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--works", type=float, nargs="+", default=[1e-4, 5e-4])
    ap.add_argument("--grids", type=int, nargs="+", default=[128, 256, 512])
    ap.add_argument("--approaches", type=int, default=5)
    ap.add_argument("--window", type=float, default=3.0, help="spacings either side")
    ap.add_argument(
        "--cell",
        type=float,
        default=None,
        metavar="APPROACH",
        help="the nine-asperity example cell at this approach [R] instead",
    )
    ap.add_argument("--discs", type=int, nargs="+", default=[60, 150])
    ap.add_argument("--seeds", type=int, nargs="+", default=[0, 1, 2])
    ap.add_argument(
        "--order",
        choices=("random", "shells"),
        default="random",
        help="the nine radii at random in the window, or each one's shells in turn",
    )
    ap.add_argument(
        "--ring",
        type=float,
        nargs="+",
        default=None,
        metavar="THICKNESS",
        help="the one-ring variant, rings this many spacings thick, instead",
    )
    ap.add_argument(
        "--reciprocal",
        type=float,
        nargs="+",
        default=None,
        metavar="APPROACH",
        help="the example cell, each edge from its own asperity's family, instead",
    )
    ap.add_argument(
        "--path",
        type=int,
        default=None,
        metavar="SAMPLES",
        help="the example cell along the check's approaches, instead",
    )
    ap.add_argument(
        "--stride", type=int, default=1, help="--path: fit every stride-th radius of an asperity"
    )
    ap.add_argument(
        "--busy", type=int, default=0, help="--path: beside this many CPU-bound processes"
    )
    args = ap.parse_args()
    if args.path:
        import subprocess
        import sys

        spin = [sys.executable, "-c", "while True: pass"]
        busy = [subprocess.Popen(spin) for _ in range(args.busy)]
        try:
            runs = {
                g: path_states(g, args.works[0], args.path, args.window, args.stride)
                for g in args.grids
            }
        finally:
            for proc in busy:
                proc.kill()
        if args.busy:
            print(f"beside {args.busy} busy processes:")
        for g, r in runs.items():
            print(
                f"{g}^2: {len(r['states'])} states, {r['discs']} discs in {r['seconds']:.1f} s "
                f"(the point-by-point path: {r['pixel_seconds']:.1f} s)"
            )
        print(
            "| approach [R] | touching | "
            + " | ".join(f"P*, alpha at {g}^2" for g in runs)
            + " | 2 alpha - alpha(M / 2) | point-by-point at the finest |"
        )
        print("| ---: " * (len(runs) + 4) + "|")
        finest = runs[args.grids[-1]]
        for i, (c, _, _, touch) in enumerate(finest["states"]):
            cells = [f"{r['states'][i][1]:.4e}, {r['states'][i][2]:.5f}" for r in runs.values()]
            rich = ""
            if len(runs) > 1:
                a = [r["states"][i][2] for r in runs.values()]
                rich = f"{2 * a[-1] - a[-2]:.5f}"
            pp, pa = finest["pixel"]
            print(
                f"| {c:.5f} | {touch} | " + " | ".join(cells) + f" | {rich} "
                f"| {pp[i]:.4e}, {pa[i]:.5f} |"
            )
        return
    if args.reciprocal:
        print(
            "| approach [R] | grid | P* | alpha | 2 alpha - alpha(M / 2) | discs | seconds "
            "| point-by-point P*, alpha | window against the cell |"
        )
        print("| ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |")
        for c in args.reciprocal:
            before = None
            for grid in args.grids:
                r = reciprocal_state(grid, args.works[0], c, args.window)
                rich = "" if before is None else f"{2 * r['alpha'] - before:.5f}"
                before = r["alpha"]
                print(
                    f"| {c:g} | {grid} | {r['p_star']:.5e} | {r['alpha']:.5f} | {rich} "
                    f"| {r['discs']} | {r['seconds']:.1f} "
                    f"| {r['pixel'][0]:.5e}, {r['pixel'][1]:.5f} | {r['window_error']:.0e} |",
                    flush=True,
                )
        return
    if args.ring:
        print("| w [E* R] | grid | ring [dx] | states | mean error of alpha | its spread (std) |")
        print("| ---: | ---: | ---: | ---: | ---: | ---: |")
        for work in args.works:
            for grid in args.grids:
                for thickness in args.ring:
                    e = ring_states(grid, work, thickness)[:, 1]
                    print(
                        f"| {work:g} | {grid} | {thickness:g} | {e.size} "
                        f"| {100 * e.mean():+.2f} % | {100 * e.std():.2f} % |",
                        flush=True,
                    )
        return
    if args.cell is not None:
        print("| grid | discs | seed | P* | alpha | point-by-point P*, alpha | seconds |")
        print("| ---: | ---: | ---: | ---: | ---: | ---: | ---: |")
        for grid in args.grids:
            for discs in args.discs:
                for seed in args.seeds:
                    r = cell_state(
                        grid, args.works[0], args.cell, discs, seed, args.window, args.order
                    )
                    print(
                        f"| {grid} | {discs} | {seed} | {r['p_star']:.4e} | {r['alpha']:.5f} "
                        f"| {r['pixel'][0]:.4e}, {r['pixel'][1]:.5f} | {r['seconds']:.1f} |",
                        flush=True,
                    )
        return
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
