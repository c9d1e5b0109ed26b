"""The surface of a design for manufacture: its height map, tiled and scaled by the
asperity radius R [m] (the validation height map, ``metainterface.validation.heightmap``,
the one height-map implementation of the package). Array row i is the line y = i * spacing,
column j is x = j * spacing; tips up, the highest tip at z = 0."""

from __future__ import annotations

import math
import re
from dataclasses import dataclass

import numpy as np

from metainterface.errors import MetainterfaceError
from metainterface.physics.cell import Design

#: Default grid: points per asperity pitch (4 a_max), so M = 64 n per cell side.
POINTS_PER_PITCH = 64
#: Largest patch side in grid points, to keep files and memory sane.
MAX_SIDE_POINTS = 8192


@dataclass(frozen=True)
class Patch:
    """A tiled height map in SI units.

    heights: (ny M, nx M) surface heights z [m], tips up, highest tip at 0 (row = y, column
    = x; periodic: the first row/column follows the last). spacing: grid step [m].
    grid: M, points per cell side. tiles: (nx, ny). cell_side: L R [m].
    """

    heights: np.ndarray
    spacing: float
    grid: int
    tiles: tuple[int, int]
    cell_side: float
    n_side: int = 1

    @property
    def size(self) -> tuple[float, float]:
        """(x, y) extent of the patch [m]: tiles times L R."""
        return self.tiles[0] * self.cell_side, self.tiles[1] * self.cell_side


def parse_tiles(text: str | tuple[int, int], *, option: str = "--tiles") -> tuple[int, int]:
    """'4x4' (or '4', or '3x2' = 3 along x, 2 along y) -> (nx, ny), each >= 1."""
    if isinstance(text, tuple):
        nx, ny = text
    else:
        match = re.fullmatch(r"\s*(\d+)\s*(?:[xX×]\s*(\d+))?\s*", str(text))
        if match is None:
            raise MetainterfaceError(
                f"{option} expects NXxNY with whole numbers >= 1 (e.g. 4x4), got {text!r}"
            )
        nx = int(match.group(1))
        ny = int(match.group(2)) if match.group(2) is not None else nx
    if isinstance(nx, bool) or isinstance(ny, bool) or int(nx) < 1 or int(ny) < 1:
        raise MetainterfaceError(f"{option} needs at least one tile each way, got {nx}x{ny}")
    return int(nx), int(ny)


def length_scale(design: Design, radius: float) -> float:
    if not (math.isfinite(radius) and radius > 0):
        raise MetainterfaceError(f"radius must be > 0, got {radius!r}")
    return radius / design.settings.radius  # metres per core length unit


def default_grid(design: Design) -> int:
    """M = 64 n grid points per cell side (64 per asperity pitch)."""
    return POINTS_PER_PITCH * design.settings.n_side


def grid_for_resolution(design: Design, radius: float, resolution: float) -> int:
    """M per cell side for ``resolution`` grid points per millimetre, rounded to a multiple of n.

    radius: R [m]. At least 2 n points per side.
    """
    if not (math.isfinite(resolution) and resolution > 0):
        raise MetainterfaceError(f"--resolution must be > 0 points per mm, got {resolution!r}")
    n = design.settings.n_side
    side_mm = design.settings.cell_side * length_scale(design, radius) * 1e3
    return n * max(2, round(side_mm * resolution / n))


def height_patch(
    design: Design, *, radius: float, tiles: tuple[int, int] = (1, 1), grid: int | None = None
) -> Patch:
    """The tiled height map of a design in metres.

    radius: R [m]; tiles: (nx, ny); grid: M points per cell side (default 64 n, a multiple
    of n). Uses the validation height map, scaled by R.
    """
    from metainterface.validation.heightmap import height_map

    nx, ny = parse_tiles(tiles)
    scale = length_scale(design, radius)
    grid = default_grid(design) if grid is None else grid
    if max(nx, ny) * grid > MAX_SIDE_POINTS:
        raise MetainterfaceError(
            f"{max(nx, ny)} tiles x {grid} points per cell = {max(nx, ny) * grid} points per "
            f"side, above {MAX_SIDE_POINTS}: lower --resolution or --tiles"
        )
    cell = height_map(design, grid)
    return Patch(
        heights=np.tile(cell.heights * scale, (ny, nx)) + 0.0,  # + 0.0: no -0.0 at the tips
        spacing=cell.spacing * scale,
        grid=cell.grid,
        tiles=(nx, ny),
        cell_side=cell.cell_side * scale,
        n_side=design.settings.n_side,
    )
