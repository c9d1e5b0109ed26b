"""The curve error of cells against a target on the target's uniform error grid, optionally
with the model's alpha scaled by a BEM-to-model ratio: the one error ``validate``, the BEM
check and ``measure`` report."""

from __future__ import annotations

from typing import Any

import numpy as np
import torch

from metainterface.physics.cell import CellSettings
from metainterface.physics.metrics import curve_error
from metainterface.physics.registry import get_model

#: Points of the uniform grid every curve error is measured on (RefineSettings.grid_points).
ERROR_POINTS = 128


def error_grid(target: tuple[np.ndarray, np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
    """(grid (ERROR_POINTS,), reference (ERROR_POINTS,)): ERROR_POINTS uniform pressures
    over [0, the target's largest P*] and the target's alpha there (linear between its
    points, 0 below its first one). target: (p_star (M,), alpha (M,)), p_star ascending."""
    p_t, a_t = (np.asarray(v, dtype=np.float64) for v in target)
    grid = np.linspace(0.0, float(p_t[-1]), ERROR_POINTS)
    return grid, np.interp(grid, p_t, a_t, left=0.0)


def ratio_on_grid(grid: np.ndarray, loads: np.ndarray, ratio: np.ndarray) -> np.ndarray:
    """A ratio alpha_bem / alpha_model known at ``loads`` (K,), on ``grid`` (G,): linear
    between the loads and held at the ends. A ratio that is not finite (NaN: a load left
    unsolved; +inf: the BEM in contact where the model is not, alpha_model = 0) counts as 1
    there: the model's alpha stands at that load, and the disagreement is not spread to the
    neighbouring grid points (where interpolating towards infinity would make it dominate)."""
    clean = np.nan_to_num(np.asarray(ratio, dtype=np.float64), nan=1.0, posinf=1.0, neginf=1.0)
    return np.interp(grid, np.asarray(loads, dtype=np.float64), clean)


def grid_curve_error(
    gamma: np.ndarray,
    h: np.ndarray,
    settings: CellSettings,
    target: tuple[np.ndarray, np.ndarray],
    model: Any = None,
    ratio: tuple[np.ndarray, np.ndarray] | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """(error (B,), coverage (B,)) of the cells (gamma, h) (B, N) [h in units of R] against
    ``target`` = (p_star (M,), alpha (M,)), measured on its :func:`error_grid`.

    The model's (``get_model(model)``, default the package's) exact alpha is computed at the
    grid's pressures; ``ratio`` = (loads (K,), alpha_bem / alpha_model (K,)) multiplies it
    (:func:`ratio_on_grid`): the BEM's error as the BEM check reports it. The error is
    :func:`~metainterface.physics.metrics.curve_error`: where a cell's curve does not reach
    the target's largest pressure (its P*_max below it), the grid points beyond its reach
    are left out of the fit and the missed share of the load range is charged as
    (1 - coverage), whatever the curve does there. coverage = min(1, P*_max / target's
    largest P*). Rows may leave the settings' gamma bounds (a made part does).
    """
    grid, ref = error_grid(target)
    g = torch.as_tensor(np.atleast_2d(np.asarray(gamma, dtype=np.float64)))
    hh = torch.as_tensor(np.atleast_2d(np.asarray(h, dtype=np.float64)))
    p = torch.as_tensor(grid)[None].expand(g.shape[0], -1).contiguous()
    with torch.no_grad():
        alpha, p_max = get_model(model).alpha_at(g, hh, settings, p, exact=True)
    alpha, p_max = alpha.numpy(), p_max.numpy()
    if ratio is not None:
        alpha = alpha * ratio_on_grid(grid, ratio[0], ratio[1])
    b = alpha.shape[0]
    err = curve_error(alpha, np.tile(ref, (b, 1)), np.tile(grid, (b, 1)), p_max)
    return np.asarray(err), np.minimum(1.0, p_max / grid[-1])
