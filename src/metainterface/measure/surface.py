"""The fitted family's surface at any point: power-law asperities on a square lattice.

A point (u, v) in cell coordinates [units of R] (u along the cell's x, v along its y, taken
modulo the cell side L) lies in the lattice cell of asperity k = (v // p) n + u // p, p = L / n,
where the surface is z = z0_k - c_k r^gamma_k, c_k = 1 / (2 R^(gamma_k - 1)), r the distance
to that cell's centre (``CellSettings.lattice_centres``). With z0 = -h (anchored) this is
the designed map of ``validation.heightmap``, evaluated off its grid (rotated scans).
"""

from __future__ import annotations

import numpy as np
import torch

from metainterface.physics.cell import CellSettings
from metainterface.physics.sneddon import shape_constant


def asperity_index(u: np.ndarray, v: np.ndarray, settings: CellSettings) -> np.ndarray:
    """Index k of the asperity owning each point (u, v) [units of R], any shape, periodic."""
    n = settings.n_side
    pitch = settings.cell_side / n
    col = np.floor(np.mod(u, settings.cell_side) / pitch).astype(np.int64) % n
    row = np.floor(np.mod(v, settings.cell_side) / pitch).astype(np.int64) % n
    return row * n + col


def lattice_surface(
    u: np.ndarray,
    v: np.ndarray,
    z0: np.ndarray,
    gamma: np.ndarray,
    settings: CellSettings,
) -> np.ndarray:
    """Heights z [units of R] at points (u, v) (any shape) of the lattice whose asperity k has
    tip height z0[k] and exponent gamma[k] (both (N,)); periodic in L."""
    k = asperity_index(u, v, settings)
    pitch = settings.cell_side / settings.n_side
    du = np.mod(u, pitch) - 0.5 * pitch
    dv = np.mod(v, pitch) - 0.5 * pitch
    g = np.asarray(gamma, dtype=np.float64)
    c = shape_constant(torch.as_tensor(g), settings.radius).numpy()
    return np.asarray(z0, dtype=np.float64)[k] - c[k] * np.hypot(du, dv) ** g[k]


def profile(r: torch.Tensor, z0: torch.Tensor, gamma: torch.Tensor, radius: float) -> torch.Tensor:
    """z = z0 - c r^gamma of one power-law asperity, broadcast (differentiable in z0, gamma)."""
    return z0 - shape_constant(gamma, radius) * r.clamp_min(0.0) ** gamma
