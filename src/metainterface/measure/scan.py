"""A measured topography read at the edge: a file through SurfaceTopography's readers (the
``measure`` extra) or a numpy array with its pixel size, in the cell's length unit R.

Array convention (the package's, ``validation.heightmap``): row index i runs along y, column
j along x, so ``heights[i, j]`` is at (x, y) = (j dx, i dy). SurfaceTopography stores
``heights[ix, iy]``; the reader transposes. Missing points (NaN, or a reader's mask) stay
masked and are counted; they are never filled.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from metainterface.errors import MetainterfaceError

#: The extra that brings the readers.
INSTALL_HINT = "pip install 'metainterface[measure]'"
#: Smallest scan side, in grid points, that can show an asperity's shape.
MIN_POINTS = 8


@dataclass(frozen=True)
class Scan:
    """A levelled-or-not height map on a regular grid, lengths in units of R.

    heights: (ny, nx) z [units of R], tips up, NaN where the instrument gave no value.
    dx, dy: pixel sizes along x (columns) and y (rows) [units of R]. radius_m: R [m], the
    scale that turned the file's metres into units of R. source: where it came from.
    """

    heights: np.ndarray
    dx: float
    dy: float
    radius_m: float
    source: str = "array"

    @property
    def shape(self) -> tuple[int, int]:
        return (int(self.heights.shape[0]), int(self.heights.shape[1]))

    @property
    def valid(self) -> np.ndarray:
        """(ny, nx) bool, True where a height was measured."""
        return np.isfinite(self.heights)

    @property
    def missing(self) -> int:
        """Number of points without a measured height."""
        return int((~self.valid).sum())

    @property
    def size(self) -> tuple[float, float]:
        """(width along x, height along y) [units of R]."""
        return (self.shape[1] * self.dx, self.shape[0] * self.dy)

    def coords(self) -> tuple[np.ndarray, np.ndarray]:
        """(x (nx,), y (ny,)) of the grid points [units of R]."""
        return np.arange(self.shape[1]) * self.dx, np.arange(self.shape[0]) * self.dy


def _length_m(value: Any, name: str) -> float:
    from metainterface.units import parse_length

    return parse_length(value, option=name)


def _height_factor(unit: str, name: str = "height_unit") -> float:
    """Metres per one ``unit`` (pint), e.g. 'um' -> 1e-6."""
    if not isinstance(unit, str) or not unit.strip():
        raise MetainterfaceError(f"{name} must be a length unit such as 'um' or 'nm'")
    return _length_m(f"1 {unit}", name)


def from_array(
    heights: Any,
    *,
    pixel_size: Any,
    radius: Any,
    height_unit: str = "m",
    source: str = "array",
) -> Scan:
    """A Scan from a (ny, nx) array (rows along y) with a pixel size.

    pixel_size: one length, or (dx, dy), with a unit ('2um') or a number in metres.
    height_unit: the unit of the array's values ('m', 'um', 'nm', ...). radius: R.
    NaN values (or a numpy masked array's mask) are missing points.
    """
    r_m = _length_m(radius, "radius")
    arr = np.ma.asarray(heights)
    if arr.ndim != 2:
        raise MetainterfaceError(f"scan must be a 2-D height map, got {arr.ndim} dimensions")
    if min(arr.shape) < MIN_POINTS:
        raise MetainterfaceError(
            f"scan must have at least {MIN_POINTS} points per side, "
            f"got {arr.shape[0]}x{arr.shape[1]}"
        )
    try:
        z = np.ma.filled(arr.astype(np.float64), np.nan)
    except (TypeError, ValueError):
        raise MetainterfaceError("scan heights must be numbers") from None
    z[~np.isfinite(z)] = np.nan
    if np.isfinite(z).sum() < MIN_POINTS**2:
        raise MetainterfaceError("scan has almost no measured points (all NaN or masked)")
    if isinstance(pixel_size, tuple | list):
        if len(pixel_size) != 2:
            raise MetainterfaceError("pixel_size must be one length or (dx, dy)")
        dx_m, dy_m = (_length_m(p, "pixel_size") for p in pixel_size)
    else:
        dx_m = dy_m = _length_m(pixel_size, "pixel_size")
    factor = _height_factor(height_unit)
    return Scan(heights=z * factor / r_m, dx=dx_m / r_m, dy=dy_m / r_m, radius_m=r_m, source=source)


def read_scan(
    path: str | os.PathLike[str],
    *,
    radius: Any,
    size: Any = None,
    height_unit: str | None = None,
) -> Scan:
    """Read a scan file with SurfaceTopography (X3P, SUR, OPD, DATX, Gwyddion, NPY, text, ...).

    The lateral size and the height unit come from the file; ``size`` (one length, or
    (width along x, height along y)) and ``height_unit`` give them where the file has none
    (or override it). radius: R. Errors are one line: file missing, unknown format, no
    lateral size, a line scan.
    """
    path = Path(path)
    if not path.is_file():
        raise MetainterfaceError(f"{path}: scan file not found")
    try:
        import SurfaceTopography as st
        from SurfaceTopography.Exceptions import CannotDetectFileFormat
    except ImportError:
        raise MetainterfaceError(
            f"reading a scan needs SurfaceTopography, which is not installed: run `{INSTALL_HINT}`"
        ) from None
    try:
        reader = st.open_topography(str(path))
    except CannotDetectFileFormat:
        raise MetainterfaceError(
            f"{path}: unknown scan format (SurfaceTopography reads X3P, SUR, OPD, DATX, GWY, "
            "NPY, plain text and more)"
        ) from None
    except Exception as exc:  # a reader's own failure on a damaged file
        first = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
        raise MetainterfaceError(f"{path}: cannot read the scan ({first})") from None
    channel = reader.default_channel
    if channel.dim != 2:
        raise MetainterfaceError(f"{path}: a line scan; measure needs a 2-D topography")
    nx, ny = channel.nb_grid_pts
    file_unit = None if channel.unit is None else str(channel.unit)
    unit = height_unit or file_unit
    if unit is None:
        raise MetainterfaceError(
            f"{path}: the file gives no height unit; give it (height_unit=, --height-unit um)"
        )
    if size is not None:
        sizes = tuple(size) if isinstance(size, tuple | list) else (size, size)
        if len(sizes) != 2:
            raise MetainterfaceError("size must be one length or (width, height)")
        sx_m, sy_m = (_length_m(s, "size") for s in sizes)
    elif channel.physical_sizes is None or file_unit is None:
        raise MetainterfaceError(
            f"{path}: the file gives no lateral size; give it (size=, or --size, e.g. 1.2mm)"
        )
    else:
        sx_m, sy_m = (
            float(s) * _height_factor(file_unit, "the file's unit") for s in channel.physical_sizes
        )
    try:  # sizes and unit given only where the file has none; the values are read as stored
        topo = reader.topography(
            physical_sizes=None if channel.physical_sizes is not None else (1.0, 1.0),
            unit=None if file_unit is not None else "m",
        )
    except Exception as exc:
        first = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
        raise MetainterfaceError(f"{path}: cannot read the scan ({first})") from None
    z = np.ma.filled(np.ma.asarray(topo.heights(), dtype=np.float64), np.nan).T  # rows along y
    if not (math.isfinite(sx_m) and math.isfinite(sy_m) and sx_m > 0 and sy_m > 0):
        raise MetainterfaceError(f"{path}: the file gives no valid lateral size")
    return from_array(
        z,
        pixel_size=(sx_m / nx, sy_m / ny),
        radius=radius,
        height_unit=unit,
        source=str(path),
    )


def as_scan(scan: Any, *, radius: Any, pixel_size: Any = None, **read: Any) -> Scan:
    """A Scan from a path (read with :func:`read_scan`), an array (with ``pixel_size``) or a
    Scan (returned as it is)."""
    if isinstance(scan, Scan):
        return scan
    if isinstance(scan, str | os.PathLike):
        if pixel_size is not None:
            raise MetainterfaceError("pixel_size is for an array; a file gives its own (or size=)")
        return read_scan(scan, radius=radius, **read)
    if pixel_size is None:
        raise MetainterfaceError("a scan given as an array needs pixel_size (e.g. '2um')")
    return from_array(scan, pixel_size=pixel_size, radius=radius, **read)
