"""The periodic height map of a unit cell (paper sec. 4.1), tips up.

The cell of side L = 4 n a_max is sampled on an M x M grid of spacing L / M, grid point
(i, j) at (x, y) = (j L / M, i L / M): row index i runs along y, column j along x, so an
array row is a line of constant y. The lattice cell of asperity k is row k // n, column
k % n (its centre from ``CellSettings.lattice_centres``); with M divisible by n every grid
point belongs to exactly one lattice cell and takes the profile of that cell's asperity,

    z = -(h_k + c_k r^gamma_k),   c_k = 1 / (2 R^(gamma_k - 1)),

r being the distance to the asperity's centre. Heights are anchored as in the forward model
(min h -> 0), so the highest tip sits at z = 0 and every other point is below it. With the
default M = 256 n the centres fall on grid points.

This is the one height-map function of the package: BEM validation and the exports use it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import torch

from metainterface import _checks
from metainterface.errors import MetainterfaceError
from metainterface.physics.cell import CellSettings, Design
from metainterface.physics.curves import anchor
from metainterface.physics.sneddon import shape_constant

#: Grid points per lattice cell in the default grid (64 per a_max, as in the paper).
POINTS_PER_ASPERITY = 256


@dataclass(frozen=True)
class HeightMap:
    """A sampled unit cell.

    heights: (M, M) surface heights z [length, units of R], tips up, highest tip at 0.
    spacing: grid spacing L / M [length]. owner: (M, M) int, the asperity each point
    belongs to (index k of the design's arrays).
    """

    heights: np.ndarray
    spacing: float
    owner: np.ndarray

    @property
    def grid(self) -> int:
        """M, points per side."""
        return int(self.heights.shape[0])

    @property
    def cell_side(self) -> float:
        """L = M * spacing [length]."""
        return self.grid * self.spacing


def default_grid(settings: CellSettings) -> int:
    """M = 256 n: 64 grid points per a_max (768 for N = 9)."""
    return POINTS_PER_ASPERITY * settings.n_side


#: Memory of one grid point in a BEM solve: heights, owner map, Tamaas's traction,
#: displacement, gap and FFT buffers (a generous count, so that a refusal is never wrong).
BYTES_PER_POINT = 160


def check_grid(grid: int, settings: CellSettings) -> int:
    """Validate M: a whole number >= 2 n that n divides; returns it as int."""
    n = settings.n_side
    if isinstance(grid, bool) or not isinstance(grid, int | np.integer):
        raise MetainterfaceError(f"grid must be a whole number, got {grid!r}")
    if grid < 2 * n or grid % n:
        raise MetainterfaceError(
            f"grid must be a multiple of the lattice side n = {n} and >= {2 * n}, got {grid}",
            argument="grid",
        )
    _checks.affordable("grid", grid, float(grid) ** 2 * BYTES_PER_POINT, what=" for the BEM")
    return int(grid)


def owner_map(n_side: int, grid: int) -> np.ndarray:
    """(M, M) int: index k = (i // m) n + j // m of the asperity owning point (i, j), m = M / n."""
    cell = np.arange(grid) // (grid // n_side)
    return cell[:, None] * n_side + cell[None, :]


def cell_height_map(
    gamma: np.ndarray, h: np.ndarray, settings: CellSettings, grid: int | None = None
) -> HeightMap:
    """Height map of one cell from its (N,) shape exponents and (N,) heights [units of R].

    grid: M points per side (default 256 n), a multiple of n. See the module docstring.
    """
    gamma_t = torch.as_tensor(np.asarray(gamma, dtype=np.float64))
    h_t = torch.as_tensor(np.asarray(h, dtype=np.float64))
    if gamma_t.ndim != 1 or gamma_t.shape != h_t.shape or gamma_t.numel() != settings.n_asperities:
        raise MetainterfaceError(
            f"gamma and h must be 1-D of length n_asperities = {settings.n_asperities}, "
            f"got shapes {tuple(gamma_t.shape)} and {tuple(h_t.shape)}"
        )
    grid = default_grid(settings) if grid is None else check_grid(grid, settings)
    spacing = settings.cell_side / grid
    owner = owner_map(settings.n_side, grid)
    coords = np.arange(grid) * spacing
    centres = settings.lattice_centres()[owner]  # (M, M, 2): (x, y) of each point's owner
    dx = coords[None, :] - centres[..., 0]  # columns run along x
    dy = coords[:, None] - centres[..., 1]  # rows run along y
    r = np.hypot(dx, dy)
    h0 = anchor(h_t[None])[0].numpy()
    c = shape_constant(gamma_t, settings.radius).numpy()
    g = gamma_t.numpy()
    heights = -(h0[owner] + c[owner] * r ** g[owner]) + 0.0  # + 0.0: tips at 0, not -0
    return HeightMap(heights=heights, spacing=spacing, owner=owner)


def height_map(design: Design, grid: int | None = None) -> HeightMap:
    """Height map of a Design on an M x M grid (default 256 n); see ``cell_height_map``."""
    return cell_height_map(design.gamma, design.h, design.settings, grid)
