"""The BEM check's own accuracy: its discretisation error, from the same design on two grids.

A BEM grid of M points per side reads the contact area with an error that falls with the
grid spacing h = L / M as h^p (a pixel on each contact's edge): on held-out random cells
(seed 5353, benchmarks/bench_check_accuracy.py --convergence) the norm of alpha_M -
alpha_{M/2} fell 3.3-3.5x from (192, 384) to (384, 768), p = 1.7-1.8, and alpha at 384^2
read 0.28-0.40 % off 768^2 (benchmarks/results/verified.md). Richardson's extrapolation
from M and M / 2,

    alpha_inf = alpha_M + (alpha_M - alpha_{M/2}) / (r^p - 1),   r = M / M_coarse,

removes that leading term (from 192^2 and 384^2 it met the 768^2 solve to 0.13-0.20 % on
those cells, about 768^2's own error, which the same order puts at 0.12-0.17 %); its
accuracy is how far it moves over the orders
the grids may have, p in ``ORDER_RANGE`` (a range around the measured 1.7-1.8), measured
as the check's curve error (norm relative to the target's):

    accuracy = max_p ||alpha_inf(p) - alpha_inf(ORDER)||_2 / ||alpha_target||_2.
"""

from __future__ import annotations

import numpy as np

#: Convergence order of the area with the grid spacing, as measured (module docstring).
ORDER = 1.8
#: Orders the accuracy covers: the measured 1.7-1.8 widened by 0.3 either way.
ORDER_RANGE = (1.5, 2.1)
#: Fewest grid points per asperity pitch of the coarse grid. Below it the area is not yet on
#: its h^p course: the built-in bilinear design at 4 loads read 8.0, 12.8, 5.0, 1.2 and
#: 0.18 % off its target at 8, 16, 32, 64 and 128 points per pitch (24^2 to 384^2), the
#: differences falling 3.8x from 32 on, erratic below; a pair from 16 (96^2 with 48^2) read
#: 5.4 % where 192^2 with 96^2 read 0.6 %.
MIN_COARSE_PER_ASPERITY = 32


def coarse_grid(grid: int, n_side: int) -> int | None:
    """The check's second grid: M / 2 rounded down to a multiple of the lattice side n; None
    where that has fewer than ``MIN_COARSE_PER_ASPERITY`` points per asperity pitch (the
    grid is too coarse to estimate its own error)."""
    coarse = (grid // 2) // n_side * n_side
    return coarse if coarse >= MIN_COARSE_PER_ASPERITY * n_side else None


def extrapolate(fine: np.ndarray, coarse: np.ndarray, ratio: float, order: float = ORDER):
    """(K,) alpha extrapolated to a grid spacing of 0 from grids ``ratio`` apart."""
    return fine + (fine - coarse) / (ratio**order - 1.0)


def accuracy(fine: np.ndarray, coarse: np.ndarray, ratio: float, alpha_target: np.ndarray) -> float:
    """The extrapolated curve's error bound, relative to ``alpha_target`` (K,) like the
    check's error: how far it moves over ``ORDER_RANGE``."""
    norm = float(np.linalg.norm(alpha_target))
    best = extrapolate(fine, coarse, ratio)
    spread = max(
        float(np.linalg.norm(extrapolate(fine, coarse, ratio, p) - best)) for p in ORDER_RANGE
    )
    return spread / norm if norm > 0 else 0.0
