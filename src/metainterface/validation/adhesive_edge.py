"""The JKR criterion's edge factor c_e (``adhesive_bem.EDGE_FACTOR``), measured on a bonded
flat punch of grid points against Kendall's K_I = F / (2 sqrt(pi a^3)), a from the punch's
pixel count: the first point to come off (``edge_factor``) and the punch pulled off through
``solve_jkr`` itself (``pull_off_factor``, the calibration)."""

from __future__ import annotations

import math

import numpy as np
import torch
from torch import Tensor

from metainterface.validation.adhesive_bem import _bonded, forward_kernel, solve_jkr


def _punch(grid: int, radius_cells: float) -> tuple[Tensor, Tensor, float]:
    """A flat punch of radius radius_cells L (L = 1) on a grid of M points: its heights
    (1, M, M) (0 on the disc, -1 off it), the disc as the contact (1, M, M), the spacing."""
    dx = 1.0 / grid
    x = (np.arange(grid) - grid / 2) * dx
    disc = np.hypot(*np.meshgrid(x, x, indexing="ij")) < radius_cells
    return torch.as_tensor(np.where(disc, 0.0, -1.0))[None], torch.as_tensor(disc)[None], dx


def _kendall_k(pressure: Tensor, points: float, dx: float) -> float:
    """Kendall's K_I of a punch of ``points`` grid points carrying ``pressure``."""
    a = math.sqrt(points * dx * dx / math.pi)
    return abs(float(pressure.sum())) * dx * dx / (2.0 * math.sqrt(math.pi * a**3))


def edge_factor(grid: int = 256, radius_cells: float = 0.125) -> float:
    """The first point to come off: a bonded flat punch of radius a = radius_cells L on a
    grid of M points, its most tensile edge point against Kendall's K_I. Returns
    max |p_edge| sqrt(dx) / K_I: 1.02-1.06, mean 1.036, over 13 radii at 256^2, above
    ``EDGE_FACTOR`` since the trimmed edge holds more than the untrimmed disc's most tensile
    point (``pull_off_factor``)."""
    heights, contact, dx = _punch(grid, radius_cells)
    fwd = forward_kernel(grid, 1.0, torch.device("cpu"))
    c = torch.full((1, 1, 1), -1e-3, dtype=torch.float64)  # a pull of 1e-3 L
    p, _ = _bonded(heights, c, contact, fwd, torch.zeros_like(heights), 1e-12, 10000)
    return float(p.abs().amax()) * math.sqrt(dx) / _kendall_k(p, float(contact.sum()), dx)


def pull_off_factor(grid: int = 128, radius_cells: float = 0.1, step: float = 0.002) -> float:
    """Calibrate c_e on the observable: a flat punch of radius a = radius_cells L (a disc of
    grid points), bonded, pulled off through ``solve_jkr`` itself with c_e = 1 in steps of
    ``step`` of the pull at which Kendall's K_I reaches K_c. Its points come off one by one
    (the most tensile first, the edge trimmed) until the punch lets go; the largest K_I of
    a stable state, a from its own pixel count, is c_e = 1's detachment K. The thresholds
    scale with c_e, so c_e = K_c / that K makes the punch come off at Kendall's force.
    Returns it."""
    side, work = 1.0, 1e-4
    z, contact, dx = _punch(grid, radius_cells)
    k_c = math.sqrt(2.0 * work)
    fwd = forward_kernel(grid, side, z.device)
    unit, _ = _bonded(z, -torch.ones(1, 1, 1, dtype=z.dtype), contact, fwd, z * 0, 1e-12, 10000)
    n0 = float(contact.sum())
    pull = k_c / _kendall_k(unit, n0, dx)  # the pull at which the bonded punch has K_c
    z_bar = -float(z.mean())
    k_max, pressure = 0.0, None
    for s in np.arange(0.8, 1.3, step):
        target = torch.tensor([z_bar + s * pull], dtype=z.dtype)
        sol = solve_jkr(z, side, target, work, contact=contact, pressure=pressure, edge=1.0)
        contact, pressure = sol.contact, sol.pressure
        n = float(contact.sum())
        if n < 0.5 * n0:
            break
        k_max = max(k_max, _kendall_k(pressure, n, dx))
    return k_c / k_max
