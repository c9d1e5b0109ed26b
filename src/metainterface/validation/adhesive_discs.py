"""An adhesive cell's path with each JKR edge found from a family of bonded discs (issue 52).

The point-by-point JKR-limit BEM (``adhesive_bem.solve_jkr``) decides a contact edge one
grid point at a time: its thresholds are pixel-scale constants, an edge pinned between them
sits within a share of K_c that no grid shrinks, and its error against JKR stops falling
past 256 points per asperity, changing sign from state to state (lattice trapping;
``benchmarks/bench_adhesive_convergence.py``). A check built on it cannot bound its own
error below a few per cent. This module decides each edge as a whole instead:

- Disc k of radius a (the grid points of asperity k's square within a of its tip), bonded
  alone in the periodic cell, is solved twice (``adhesive_bem._bonded``, the point-by-point
  BEM's own bonded solver): for the heights at zero approach and for a unit approach. Its
  force at approach c is F_0k(a) + c k_k(a). Under the other asperities' displacement u_ext
  it carries, by reciprocity, F_k(a) = F_0k(a) + (c - u_0) k_k(a) - u_2 M2_k(a), with u_ext
  fitted by u_0 + u_2 r^2 over the disc (a tilt, which a centred disc does not feel, is
  fitted and dropped) and M2_k = sum(p1 r^2) of the unit approach's pressure p1. F_0k, k_k
  and M2_k depend neither on c nor on the others: each disc is solved once for a whole path
  (``DiscCell.family``), on a window about its asperity with the cell's kernel cut to the
  window and zero-padded (a linear convolution: exact for each pair of the window's points).
- F_k and k_k are fitted by cubics in a = sqrt(A / pi) (A the disc's area in points) over
  every ``stride``-th distinct radius within ``WINDOW`` spacings of the edge: the fit
  smooths the pixels' staircase that pins the point-by-point edge.
- The edge is where the stress intensity the fit gives equals K_c = sqrt(2 E* w) (Maxwell's
  relation on the periodic cell: K = -dF/da / sqrt(2 pi a |dk/da| / E*)), the root at which
  K - K_c rises through 0 (a stable edge).
- The edges and u_ext are iterated with coupled solves of all the touching discs until no
  edge moves by more than ``SETTLE`` spacings (``DiscCell.settle``); an asperity joins where
  its tip's gap under the settled state falls below 0 (``disc_path``).

The criterion's error then falls as the grid spacing, with one sign (on a Hertz asperity
against JKR: +1.4 to +2.9 % at 128 points per asperity, +0.7 to +1.4 % at 256, +0.25 to
+0.7 % at 512), so two grids remove it (Richardson) and a third tells what is left
(``verify.adhesive``; ``benchmarks/bench_adhesive_subpixel.py``, figures in
benchmarks/results/adhesion.md). It assumes round contacts centred on their tips: where an
edge cannot be found in its asperity's square, or a contact reaches the square's side, it
raises ``DiscCriterionError`` (the check then falls back on the point-by-point BEM).
"""

from __future__ import annotations

import math
import threading
import time

import numpy as np
import torch

from metainterface._threads import stop_asked
from metainterface.errors import MetainterfaceError
from metainterface.physics.cell import Design
from metainterface.physics.sneddon import shape_constant
from metainterface.validation._disc_windows import padded, window_kernels
from metainterface.validation.adhesive_bem import (
    PRECONDITIONER_DTYPE,
    _apply,
    _bonded,
    _spectral,
    forward_kernel,
    inverse_kernel,
)
from metainterface.validation.adhesive_path import AdhesivePath

#: Spacings either side of an edge over which a family is fitted.
WINDOW = 3.0
#: Every ``STRIDE``-th of an asperity's distinct radii is solved and fitted: on the benchmark
#: cell a stride of 3 moves the two-grid alpha by at most 0.07 % against every radius, at a
#: third of the cost (benchmarks/results/adhesion.md).
STRIDE = 3
#: Fewer strided radii than this in a fit's window, and the fit takes every radius there.
MIN_FIT = 8
#: Relative residual of the discs' bonded solves (the fits read their sums to ~1e-6), and of
#: the coupled solves of the touching discs.
FAMILY_TOLERANCE = 1e-9
COUPLED_TOLERANCE = 1e-10
MAX_ITER = 5000
#: The edges are settled when none moves by more than this share of a spacing.
SETTLE = 0.05
#: Settling rounds and window moves at most before the criterion gives up.
ROUNDS = 8
MOVES = 40


class DiscCriterionError(MetainterfaceError):
    """The disc criterion does not apply to this cell (an edge not found in its asperity's
    square, or a contact reaching the square's side)."""


def _pair(
    z: torch.Tensor, sets: torch.Tensor, fwd, stiff, start: torch.Tensor | None, tolerance: float
) -> torch.Tensor:
    """(2, M, M) the pressures of the points ``sets`` (M, M) bool of the surface ``z``
    (M, M) bonded at zero approach and for a unit approach. Raises MetainterfaceError
    where the conjugate gradient does not reach ``tolerance``."""
    pair = torch.stack([z, torch.zeros_like(z)])
    shift = torch.tensor([0.0, 1.0], dtype=z.dtype, device=z.device).reshape(2, 1, 1)
    mask = sets[None].expand(2, -1, -1)
    first = torch.zeros_like(pair) if start is None else start * mask
    p, res = _bonded(pair, shift, mask, fwd, first, tolerance, MAX_ITER, stiff)
    if not bool((res <= tolerance).all()):
        raise MetainterfaceError(
            f"adhesive BEM (disc criterion) did not converge: conjugate-gradient residual "
            f"{float(res.max()):.3g} > tolerance {tolerance:g} after {MAX_ITER} iterations"
        )
    return p


class DiscCell:
    """One design on ``grid``^2 for the disc criterion (see the module's doc).

    work: w [E* length] in the cell's units; last: the last approach [length] of the path
    it will be loaded along (it sizes the windows: the rigid overlap's radius there, by half
    again, plus the fit's window; a window too small for an edge is grown); stride: every
    stride-th distinct radius of an asperity is fitted. ``family`` is safe to call from two
    threads (each window's solve is independent; a radius solved twice is the same)."""

    def __init__(
        self,
        design: Design,
        grid: int,
        work: float,
        last: float,
        *,
        stride: int = STRIDE,
        device: torch.device | str = "cpu",
    ) -> None:
        from metainterface.validation.heightmap import height_map

        s = design.settings
        self.n = int(design.gamma.size)
        self.grid, self.work = grid, work
        self.device = torch.device(device)
        hm = height_map(design, grid)
        self.heights, self.own = hm.heights, hm.owner
        self.side, self.dx = hm.cell_side, hm.spacing
        centres = s.lattice_centres()[self.own]
        x = np.arange(grid) * self.dx
        self.off_x, self.off_y = x[None, :] - centres[..., 0], x[:, None] - centres[..., 1]
        self.dist = np.hypot(self.off_x, self.off_y)
        self.tips = np.array(
            [int(np.argmin(np.where(self.own == k, self.dist, np.inf))) for k in range(self.n)]
        )
        self.z_tip = self.heights.reshape(-1)[self.tips]
        # each asperity's distinct radii about its tip; a fit takes every stride-th
        # (``radii_near``)
        self.stride = stride
        self.shells = [np.unique(np.round(self.dist[self.own == k], 12)) for k in range(self.n)]
        self.square = grid // s.n_side  # points along an asperity's square
        self._shape = shape_constant(torch.as_tensor(design.gamma), s.radius).numpy()
        self._gamma = np.asarray(design.gamma, dtype=np.float64)
        radius = self.overlap_radius(np.arange(self.n), last)
        reach = np.ceil(1.5 * radius / self.dx + WINDOW + 3).astype(int)
        self.m = [min(self.square, 2 * int(r)) + 2 for r in reach]
        dev = self.device
        self.fwd = _spectral(forward_kernel(grid, self.side, dev), torch.complex128)
        self.stiff = _spectral(inverse_kernel(grid, self.side, dev), PRECONDITIONER_DTYPE)
        self.z = torch.as_tensor(self.heights, device=dev)
        self.own_t = torch.as_tensor(self.own, device=dev)
        self.kernel = torch.fft.irfft2(
            forward_kernel(grid, self.side, dev)[0].to(torch.complex128), s=(grid, grid)
        )
        self._kernels: dict[int, tuple] = {}
        self._windows: dict[int, tuple] = {}
        self._last: dict[int, torch.Tensor] = {}  # each window's last pressure: a warm start
        self.cache: dict[tuple[int, int], tuple[float, float, float, float]] = {}
        self._lock = threading.Lock()
        self.coupled_pair: torch.Tensor | None = None  # the last coupled solve: a warm start

    def _window(self, k: int) -> tuple:
        """Asperity k's window (its square's m x m points about the tip, zero-padded):
        the distances to the tip (inf off it), its own points, heights and kernels."""
        with self._lock:
            if k not in self._windows:
                m, grid = self.m[k], self.grid
                if m not in self._kernels:
                    self._kernels[m] = window_kernels(self.kernel, grid, m, self.dx)
                cy, cx = divmod(int(self.tips[k]), grid)
                rows, cols = np.ix_(
                    (np.arange(m) + cy - m // 2) % grid, (np.arange(m) + cx - m // 2) % grid
                )
                pad = padded(m)
                zw, dw = np.zeros((pad, pad)), np.full((pad, pad), np.inf)
                mine = np.zeros((pad, pad), dtype=bool)
                block = self.dist[rows, cols]
                zw[:m, :m], mine[:m, :m] = self.heights[rows, cols], self.own[rows, cols] == k
                dw[:m, :m] = np.where(mine[:m, :m], block, np.inf)
                # the largest disc about the tip inside both the window and the square
                rim = np.ones((m, m), dtype=bool)
                rim[1:-1, 1:-1] = False
                inside = float(block[rim | ~mine[:m, :m]].min())
                r2 = torch.as_tensor(np.where(mine, dw, 0.0) ** 2, device=self.device)
                self._windows[k] = (
                    torch.as_tensor(dw, device=self.device),
                    torch.as_tensor(zw, device=self.device),
                    r2,
                    self._kernels[m],
                    inside,
                )
            return self._windows[k]

    def _grow(self, k: int) -> bool:
        """Asperity k's window doubled (at most its square); False where it is already the
        square. The discs solved so far stay valid: each window's solve is exact."""
        with self._lock:
            if self.m[k] >= self.square + 2:
                return False
            self.m[k] = min(self.square, 2 * (self.m[k] - 2)) + 2
            self._windows.pop(k, None)
            self._last.pop(k, None)
            return True

    def family(self, k: int, j: int) -> tuple[float, float, float, float]:
        """Disc j (the j-th distinct radius) of asperity k alone in the cell: (a [length],
        F_0k, k_k, M2_k) [E* length^2, E* length, E* length^3]."""
        key = (k, j)
        got = self.cache.get(key)
        if got is not None:
            return got
        dw, zw, r2, (fwd, stiff), _ = self._window(k)
        r = float(self.shells[k][j])
        disc = dw <= r + 1e-12
        last = self._last.get(k)
        start = last if last is not None and last.shape[-1] == zw.shape[-1] else None
        p = _pair(zw, disc, fwd, stiff, start, FAMILY_TOLERANCE)
        self._last[k] = p
        area = self.dx * self.dx
        out = (
            math.sqrt(float(disc.sum()) / math.pi) * self.dx,
            float(p[0].sum()) * area,
            float(p[1].sum()) * area,
            float((p[1] * r2).sum()) * area,
        )
        self.cache[key] = out
        return out

    def radii_near(self, k: int, centre: float) -> np.ndarray:
        """Indices of asperity k's radii to fit within ``WINDOW`` spacings of ``centre``."""
        near = np.flatnonzero(np.abs(self.shells[k] - centre) < WINDOW * self.dx)
        every = near[near % self.stride == 0]
        # a contact a few spacings wide has few distinct radii about its edge: all of them,
        # where every stride-th would leave fewer than MIN_FIT (on a coarse grid a third of
        # the states went unplaced without it)
        return every if every.size >= MIN_FIT else near

    def prefill(self, ranges: dict[int, tuple[float, float]], done: threading.Event) -> int:
        """Solve the families of asperities ``ranges`` (k: (lo, hi) radii [length]) ahead of
        a path that will need them (each within ``WINDOW`` spacings of [lo, hi]), until
        ``done`` is set. Returns the discs solved."""
        count = 0
        for k, (lo, hi) in ranges.items():
            reach = WINDOW * self.dx
            shells = self.shells[k]
            wanted = np.flatnonzero((shells > lo - reach) & (shells < hi + reach))
            for j in wanted[wanted % self.stride == 0]:
                if done.is_set() or stop_asked():
                    return count
                if (k, int(j)) not in self.cache:
                    self.family(k, int(j))
                    count += 1
        return count

    def overlap_radius(self, k: np.ndarray, c: float) -> np.ndarray:
        """(len(k),) the rigid overlap's radius [length] of asperities k at approach c: a
        first guess of a new contact's edge (adhesion holds it wider)."""
        overlap = np.maximum(c + self.z_tip[k], 0.0)
        return (overlap / self._shape[k]) ** (1.0 / self._gamma[k])  # z = -(h + c_k r^gamma)

    def coupled(self, c: float, rho: np.ndarray, touching: np.ndarray) -> torch.Tensor:
        """(2, M, M) the touching discs (radii ``rho`` (N,)) bonded together, at zero and
        unit approach: the pressure at approach c is p[0] + c p[1]."""
        sets = np.isin(self.own, touching) & (self.dist <= rho[self.own] + 1e-12)
        p = _pair(
            self.z,
            torch.as_tensor(sets, device=self.device),
            self.fwd,
            self.stiff,
            self.coupled_pair,
            COUPLED_TOLERANCE,
        )
        self.coupled_pair = p
        return p

    def settle(
        self, c: float, rho: np.ndarray, touching: np.ndarray
    ) -> tuple[np.ndarray, float, torch.Tensor]:
        """The edges (N,) [length] at approach c from the radii ``rho``, the cell's force
        there [E* length^2] and the last coupled pressure (M, M) [E*]."""
        dx = self.dx
        k_c = math.sqrt(2.0 * self.work)
        s = np.linspace(-(WINDOW - 1) * dx, (WINDOW - 1) * dx, 4001)
        rho = rho.copy()
        force, pressure = 0.0, None
        for _ in range(ROUNDS):
            pair = self.coupled(c, rho, touching)
            pressure = pair[0] + c * pair[1]
            others = torch.stack([pressure * (self.own_t != k) for k in touching])
            u_ext = _apply(others, self.fwd).cpu().numpy()
            edge, force = rho.copy(), 0.0
            for i, k in enumerate(touching):
                near = (self.own == k) & (self.dist <= rho[k] + WINDOW * dx)
                basis = np.column_stack(
                    [np.ones(near.sum()), self.dist[near] ** 2, self.off_x[near], self.off_y[near]]
                )
                u0, u2 = np.linalg.lstsq(basis, u_ext[i][near], rcond=None)[0][:2]
                edge[k], f = self._edge(int(k), c, u0, u2, max(rho[k], WINDOW * dx), s, k_c)
                force += f
            moved = float(np.abs(edge - rho)[touching].max()) / dx
            rho = edge
            if moved < SETTLE:
                break
        return rho, force, pressure

    def _edge(
        self, k: int, c: float, u0: float, u2: float, centre: float, s: np.ndarray, k_c: float
    ) -> tuple[float, float]:
        """Asperity k's stable edge [length] and force there, its family's window moved
        until the edge lies inside it."""
        dx = self.dx
        edge_max = self._window(k)[4] - WINDOW * dx
        least = step = (WINDOW - 1) * dx  # a move keeps the fitted intervals overlapping
        below, above = 0.0, math.inf  # the edge lies beyond ``below`` and short of ``above``
        for _ in range(MOVES):
            near = self.radii_near(k, centre)
            if centre + WINDOW * dx > self._window(k)[4] and self._grow(k):
                edge_max = self._window(k)[4] - WINDOW * dx
            if near.size < 5:
                break
            a, f0, kk, m2 = np.array([self.family(k, int(j)) for j in near]).T
            cf = np.polyfit(a - centre, f0 + (c - u0) * kk - u2 * m2, 3)
            ck = np.polyfit(a - centre, kk, 3)
            # K - K_c in force units: K from -dF/da (a tensile edge: the force falls as the
            # disc grows); it rises through 0 at the stable edge
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
                at = float(s[up[np.argmin(np.abs(s[up]))]])
                if centre + at <= edge_max:
                    return centre + at, float(np.polyval(cf, at))
                if not self._grow(k):
                    break
                edge_max = self._window(k)[4] - WINDOW * dx
                continue
            # the edge lies further out where K stays below K_c at the window's end: search
            # there, doubling the step until the edge is bracketed (a snap-in's edge can be
            # tens of spacings from the first guess), then halving the bracket
            if balance[-1] < 0:
                below = centre
            else:
                above = centre
            if above - below < least:
                break
            if math.isinf(above):
                centre, step = centre + step, 2 * step
            else:
                centre = max(0.5 * (below + above), WINDOW * dx)
            if centre > edge_max and not self._grow(k):
                break
            edge_max = self._window(k)[4] - WINDOW * dx
        raise DiscCriterionError(
            f"the disc criterion found no edge for asperity {k} at approach {c:.4g} within its "
            "square (its contact is not a round one about its tip there)"
        )


def disc_path(
    cell: DiscCell,
    approaches: np.ndarray,
    *,
    stop_above: float | None = None,
    skip_failures: bool = False,
) -> AdhesivePath:
    """``cell`` loaded along rising ``approaches`` (K,) [length], each state settled from
    the one before; an asperity joins where its tip's gap under the settled state falls
    below 0 (its first edge guessed at its rigid overlap's radius). ``stop_above``: a P*
    after whose first state the loading stops. ``skip_failures``: a state whose edge the
    criterion does not find is NaN (P*, alpha) and the path goes on from the state before,
    instead of raising DiscCriterionError (for a grid that only estimates an error). Returns
    the path with ``touching`` and ``asperity_alpha`` (K, N); its ``residual`` is the
    coupled solves' tolerance."""
    n, dx, area = cell.n, cell.dx, cell.side**2
    rho = np.zeros(n)
    touching = np.zeros(0, dtype=int)
    rows: list[tuple] = []
    for c in np.asarray(approaches, dtype=np.float64):
        if stop_asked():
            break
        t0 = time.perf_counter()
        force = 0.0
        for _ in range(n + 1):
            if touching.size:
                try:
                    rho, force, pressure = cell.settle(float(c), rho, touching)
                except DiscCriterionError:
                    if not skip_failures:
                        raise
                    force = math.nan
                    break
                u = _apply(pressure[None], cell.fwd)[0].cpu().numpy()
                gap = u.reshape(-1)[cell.tips] - cell.z_tip - c
            else:
                gap = -cell.z_tip - c
            new = np.setdiff1d(np.flatnonzero(gap < 0), touching)
            if not new.size:
                break
            rho[new] = np.maximum(cell.overlap_radius(new, float(c)), WINDOW * dx)
            touching = np.union1d(touching, new)
        on = np.zeros(n, dtype=bool)
        on[touching] = True
        share = (
            np.where(on, math.pi * rho**2, 0.0) / area * (1.0 if math.isfinite(force) else math.nan)
        )
        rows.append(
            (float(c), force / area, float(share.sum()), on, share, time.perf_counter() - t0)
        )
        if stop_above is not None and force / area > stop_above:
            break
    k = len(rows)
    p = np.array([r[1] for r in rows])
    top = np.fmax.accumulate(p) if k else p
    return AdhesivePath(
        approach=np.array([r[0] for r in rows]),
        p_star=p,
        alpha=np.array([r[2] for r in rows]),
        loading=np.ones(k, dtype=bool),
        on_branch=(p >= top) & (p > 0),
        touching=np.array([r[3] for r in rows]).reshape(k, n),
        asperity_alpha=np.array([r[4] for r in rows]).reshape(k, n),
        residual=np.full(k, COUPLED_TOLERANCE),
        seconds=np.array([r[5] for r in rows]),
    )
