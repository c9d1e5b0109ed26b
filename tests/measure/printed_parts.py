"""Prints and scans made the way a lab makes them, independently of the package's own code.

A *print* (:class:`Process`) turns a design into a made surface in metres: the exponents
shifted, the offsets scaled, every tip cut flat ``flat_depth`` below its apex, and the
whole surface put on the printer's layers (``layer``: each height rounded to the nearest
level ``phase + k layer``, measured from the design's datum, the tallest tip's apex). A
*scan* (:func:`scan_print`) looks at a patch of such a part the way an instrument does: its
own axes at any angle to the part's (90, 180, 270 degrees and a few more), optionally with
its y axis the other way round (a mirrored file), every pixel the mean of the surface over
its footprint (4 x 4 samples: the blur a real pixel has), a tilt, noise, missing points. It
is written the way instruments export: a plain text matrix in micrometres, rows along y.

Nothing here calls the package's surface, lattice or height-map code; only the design's
numbers (gamma, h, the lattice's geometry) are read. The made cell on any grid
(:func:`made_cell`) is the reference that the measurement is held against.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

import metainterface as mi


@dataclass(frozen=True)
class Process:
    """How a printer makes a design. gamma_shift: added to every exponent; h_scale: the
    offsets scaled; flat_depth [m]: each tip cut flat this far below its apex (0: sharp);
    layer [m]: layer height (0: continuous); phase [m]: the layer levels' offset from the
    datum (the tallest designed tip's apex); debris: a Gaussian lump (u, v, height, radius)
    [m] stuck to the part (once, not in every cell)."""

    gamma_shift: float = 0.0
    h_scale: float = 1.0
    flat_depth: float = 0.0
    layer: float = 0.0
    phase: float = 0.0
    debris: tuple[float, float, float, float] | None = None  # (u, v, height, radius) [m]


def made_height(u: np.ndarray, v: np.ndarray, design: mi.Design, p: Process, radius: float):
    """Heights [m] of the made part at part coordinates (u, v) [m] (tips up, periodic)."""
    n = math.isqrt(design.n_asperities)
    # the lattice: the design's cell side, a multiple of R
    side = design.settings.cell_side * radius
    pitch = side / n
    gamma = design.gamma + p.gamma_shift
    h = p.h_scale * (design.h - design.h.min()) * radius
    col = np.floor(u / pitch).astype(np.int64)
    row = np.floor(v / pitch).astype(np.int64)
    k = np.mod(row, n) * n + np.mod(col, n)
    r = np.hypot(u - (col + 0.5) * pitch, v - (row + 0.5) * pitch)
    g = gamma[k]
    apex = -h[k]
    z = apex - r**g / (2.0 * radius ** (g - 1.0))
    if p.flat_depth > 0:
        z = np.minimum(z, apex - p.flat_depth)
    if p.layer > 0:
        z = p.phase + p.layer * np.floor((z - p.phase) / p.layer + 0.5)
    if p.debris is not None:
        u0, v0, height, width = p.debris
        z = z + height * np.exp(-((u - u0) ** 2 + (v - v0) ** 2) / (2 * width**2))
    return z


def made_cell(design: mi.Design, p: Process, radius: float, grid: int) -> np.ndarray:
    """(grid, grid) heights [m] of one unit cell of the made part, rows along v, sampled at
    the pixel centres (the reference's own grid)."""
    side = design.settings.cell_side * radius
    c = (np.arange(grid) + 0.5) * side / grid
    uu, vv = np.meshgrid(c, c)
    return made_height(uu, vv, design, p, radius)


@dataclass(frozen=True)
class Scanner:
    """An instrument's view of the part. pixel [m]; points: (nx, ny); angle_deg: the part's
    lattice axes against the instrument's x axis; mirrored: the file's y axis runs the other
    way; offset: where the part's origin is in the scan, in pixels; tilt: (dz/dx, dz/dy);
    noise [m] (Gaussian, per pixel); missing: share of points dropped; supersample: samples
    per pixel side averaged into a pixel."""

    pixel: float
    points: tuple[int, int]
    angle_deg: float = 0.0
    mirrored: bool = False
    offset: tuple[float, float] = (37.3, 21.9)
    tilt: tuple[float, float] = (0.0, 0.0)
    noise: float = 0.0
    missing: float = 0.0
    supersample: int = 4
    seed: int = 0


def scan_print(design: mi.Design, p: Process, radius: float, sc: Scanner) -> np.ndarray:
    """The scan's (ny, nx) heights [m] as the instrument writes them (rows along its y)."""
    nx, ny = sc.points
    s = sc.supersample
    sub = (np.arange(s) + 0.5) / s - 0.5
    jj = (np.arange(nx)[:, None] + sub[None]).ravel()  # (nx s,)
    ii = (np.arange(ny)[:, None] + sub[None]).ravel()
    x, y = np.meshgrid((jj - sc.offset[0]) * sc.pixel, (ii - sc.offset[1]) * sc.pixel)
    t = math.radians(sc.angle_deg)
    u = math.cos(t) * x + math.sin(t) * y
    v = -math.sin(t) * x + math.cos(t) * y
    z = made_height(u, v, design, p, radius)
    z = z.reshape(ny, s, nx, s).mean(axis=(1, 3))  # each pixel: its footprint's mean
    xs, ys = np.meshgrid(np.arange(nx) * sc.pixel, np.arange(ny) * sc.pixel)
    z = z + sc.tilt[0] * xs + sc.tilt[1] * ys + 3.7e-6
    rng = np.random.default_rng(sc.seed)
    if sc.noise:
        z = z + rng.normal(0.0, sc.noise, z.shape)
    if sc.missing:
        z[rng.random(z.shape) < sc.missing] = np.nan
    if sc.mirrored:
        z = z[::-1]
    return z


def write_text_matrix(z: np.ndarray, path) -> None:
    """A plain text matrix in micrometres, one scan row per line (NaN for no value), as
    profilometer software exports it: no header, no size, no unit."""
    np.savetxt(path, z * 1e6, fmt="%.5f")
