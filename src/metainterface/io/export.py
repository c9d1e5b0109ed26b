"""Exports for manufacture: the height map of a cell or tiled patch, and a printable STL.

The surface is the validation height map (``metainterface.validation.heightmap``, the one
height-map implementation of the package) of one cell, tiled ``tiles = (nx, ny)`` times and
scaled by the asperity radius R [m]. Array row i is the line y = i * spacing, column j is
x = j * spacing; tips up, the highest tip at z = 0.

Formats (library chosen for each):
  npy   float64 heights in metres (numpy).
  png   16-bit grayscale (Pillow), white = high; tiff: the same (tifffile), with the pixel size
        in the resolution tags. z = z_min + level * scale, written in the sidecar.
  stl   binary STL in millimetres (trimesh): the tiled surface on a base plate of thickness
        ``base`` below the lowest point; top grid triangles, four side walls and a bottom fan
        that share every edge, so the mesh is watertight (checked before writing).

Every export writes a sidecar ``OUT.json`` (``patch.png`` -> ``patch.png.json``) with the
height scale, the grid, the tiling and the provenance.
"""

from __future__ import annotations

import io
import json
import math
import os
import re
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from metainterface._files import strict_json
from metainterface._files.atomic import write_bytes, write_text
from metainterface._files.provenance import provenance
from metainterface._names import EXPORT_FORMATS
from metainterface.errors import MetainterfaceError
from metainterface.physics.cell import Design

FORMATS = EXPORT_FORMATS
SUFFIXES = {".stl": "stl", ".png": "png", ".tif": "tiff", ".tiff": "tiff", ".npy": "npy"}
#: Default grid: points per asperity pitch (4 a_max), so M = 64 n per cell side.
POINTS_PER_PITCH = 64
#: Largest patch side in grid points, and largest STL, to keep files and memory sane.
MAX_SIDE_POINTS = 8192
MAX_STL_TRIANGLES = 8_000_000
_LEVELS = 65535
#: Files larger than this [bytes] are written only when asked (``force``): the size is
#: stated first, with ways to make the file smaller.
LARGE_FILE_BYTES = 100 * 10**6
#: STL flanks: outside the contact zone of each asperity (a_max from its centre, with this
#: margin) the surface is meshed on every FLANK_STEP-th grid line only by default.
FLANK_STEP = 4
CONTACT_MARGIN = 1.15


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


def format_for(path: str | os.PathLike[str], fmt: str | None = None) -> str:
    """The export format: ``fmt`` if given (checked against a known suffix), else the suffix."""
    suffix = Path(path).suffix.lower()
    if fmt is None:
        if suffix not in SUFFIXES:
            raise MetainterfaceError(
                f"cannot tell the format of {path}: give --format ({'|'.join(FORMATS)}) or a "
                f"suffix {', '.join(SUFFIXES)}"
            )
        return SUFFIXES[suffix]
    fmt = fmt.lower()
    if fmt == "tif":
        fmt = "tiff"
    if fmt not in FORMATS:
        raise MetainterfaceError(f"--format must be one of {'|'.join(FORMATS)}, got {fmt!r}")
    if suffix in SUFFIXES and SUFFIXES[suffix] != fmt:
        raise MetainterfaceError(f"--out {path} has a {SUFFIXES[suffix]} suffix but --format {fmt}")
    return fmt


def _scale(design: Design, radius: float) -> float:
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
    side_mm = design.settings.cell_side * _scale(design, radius) * 1e3
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
    scale = _scale(design, radius)
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


def mesh_lines(patch: Patch, flank_step: int = 1) -> tuple[np.ndarray, np.ndarray]:
    """The grid lines (node indices along x and y, 0 .. nx M inclusive, the last closing
    the period) an STL of the patch is meshed on: every line through an asperity's
    contact zone (within CONTACT_MARGIN a_max of its centre line, a_max = pitch / 4), every
    ``flank_step``-th across the flanks between them, and the patch's edges."""
    ny, nx = patch.heights.shape
    m = patch.grid // patch.n_side  # grid points per asperity pitch

    def lines(count: int) -> np.ndarray:
        i = np.arange(count + 1)
        offset = (i % m) / m - 0.5  # from the centre line, in pitches (-0.5 .. 0.5)
        fine = np.abs(offset) <= CONTACT_MARGIN / 4 + 0.5 / m
        keep = fine | (i % max(1, flank_step) == 0) | (i == count)
        return np.flatnonzero(keep)

    return lines(nx), lines(ny)


def stl_triangles(n_x: int, n_y: int) -> int:
    """Triangles of an STL meshed on n_x x n_y grid lines: the top, the four walls and the
    bottom fan (see :func:`patch_mesh`)."""
    loop = 2 * (n_x - 1) + 2 * (n_y - 1)
    return 2 * (n_x - 1) * (n_y - 1) + 3 * loop


def file_bytes(patch: Patch, fmt: str, flank_step: int = 1) -> int:
    """The size of the export [bytes] (at most, for the compressed PNG)."""
    ny, nx = patch.heights.shape
    if fmt == "stl":
        lx, ly = mesh_lines(patch, flank_step)
        return 84 + 50 * stl_triangles(lx.size, ly.size)
    return nx * ny * (8 if fmt == "npy" else 2) + 1024


def _require(module: str, what: str) -> Any:
    """Import an optional export library, or a one-line error with the install command."""
    import importlib

    try:
        return importlib.import_module(module)
    except ImportError:
        raise MetainterfaceError(
            f"{what} export needs {module}, which is not installed: run "
            "`pip install 'metainterface[export]'`"
        ) from None


def patch_mesh(patch: Patch, base: float, flank_step: int = 1) -> Any:
    """A watertight trimesh.Trimesh of the patch on a base plate, in millimetres.

    base: plate thickness under the lowest surface point [m], > 0. The bottom face is at
    z = 0, the grid spans [0, nx L R] x [0, ny L R]; the last row and column close the
    period (they repeat the first). Faces are wound outwards. flank_step: mesh the flanks
    between the asperities' contact zones on every flank_step-th grid line only
    (:func:`mesh_lines`; 1 = every line); a tensor grid, so it stays watertight.
    """
    trimesh = _require("trimesh", "STL")
    if not (math.isfinite(base) and base > 0):
        raise MetainterfaceError(f"--base must be > 0 for an STL, got {base!r}")
    cols, rows = mesh_lines(patch, flank_step)
    n_tri = stl_triangles(cols.size, rows.size)
    if n_tri > MAX_STL_TRIANGLES:
        raise MetainterfaceError(
            f"the STL would have {n_tri} triangles, above {MAX_STL_TRIANGLES}: "
            f"lower --resolution or --tiles, or raise --flank-step"
        )
    z = np.pad(patch.heights, ((0, 1), (0, 1)), mode="wrap")[np.ix_(rows, cols)]
    ny, nx = rows.size - 1, cols.size - 1  # cells of the mesh; nodes are one more each way
    z_mm = (z - z.min()) * 1e3 + base * 1e3
    step_mm = patch.spacing * 1e3
    ys, xs = np.meshgrid(rows * step_mm, cols * step_mm, indexing="ij")
    top = np.column_stack([xs.ravel(), ys.ravel(), z_mm.ravel()])
    idx = np.arange(top.shape[0]).reshape(ny + 1, nx + 1)
    v00, v10 = idx[:-1, :-1].ravel(), idx[:-1, 1:].ravel()
    v01, v11 = idx[1:, :-1].ravel(), idx[1:, 1:].ravel()
    faces_top = np.concatenate([np.column_stack([v00, v10, v11]), np.column_stack([v00, v11, v01])])
    # Boundary loop, counter-clockwise seen from above: y = 0, x = X, y = Y, x = 0.
    loop = np.concatenate([idx[0, :-1], idx[:-1, -1], idx[-1, :0:-1], idx[:0:-1, 0]])
    n_loop = loop.size
    bottom = top[loop].copy()
    bottom[:, 2] = 0.0
    centre = np.array([[xs[0, -1] / 2, ys[-1, 0] / 2, 0.0]])
    b0 = top.shape[0]
    k = np.arange(n_loop)
    t_k, t_k1 = loop, np.roll(loop, -1)
    b_k, b_k1 = b0 + k, b0 + (k + 1) % n_loop
    c = np.full(n_loop, b0 + n_loop)
    faces = np.concatenate(
        [
            faces_top,
            np.column_stack([t_k, b_k, b_k1]),
            np.column_stack([t_k, b_k1, t_k1]),
            np.column_stack([c, b_k1, b_k]),
        ]
    )
    mesh = trimesh.Trimesh(
        vertices=np.concatenate([top, bottom, centre]), faces=faces, process=False
    )
    # Outward winding (positive volume) is fixed by construction and tested; closure, and
    # what the file will hold (float32 millimetres), are checked on every mesh.
    check_mesh(mesh)
    return mesh


def check_mesh(mesh: Any) -> None:
    """Refuse an STL that would be wrong: coordinates not finite in float32 (the STL's
    type), triangles of zero area at that precision, not closed, or of no volume."""
    v32 = np.asarray(mesh.vertices, dtype=np.float64).astype(np.float32)
    if not np.isfinite(v32).all():
        raise MetainterfaceError(
            "the STL's coordinates are not finite in single precision; check --radius and "
            "the design's heights"
        )
    tri = v32[np.asarray(mesh.faces)].astype(np.float64)
    area2 = np.linalg.norm(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]), axis=1)
    if len(mesh.faces) == 0 or not (area2 > 0).all():
        raise MetainterfaceError(
            f"the STL has {int((area2 <= 0).sum())} triangles of zero area in single precision;"
            " check --radius and --resolution"
        )
    if not (mesh.is_watertight and mesh.is_winding_consistent and mesh.volume > 0):
        raise MetainterfaceError("the STL mesh is not closed and consistently wound; not written")


def _quantise(heights: np.ndarray) -> tuple[np.ndarray, dict[str, float]]:
    z_min, z_max = float(heights.min()), float(heights.max())
    step = (z_max - z_min) / _LEVELS if z_max > z_min else 1.0
    levels = np.rint((heights - z_min) / step).astype(np.uint16)
    return levels, {
        "z_min_m": z_min,
        "z_max_m": z_max,
        "height_scale_m_per_level": step,
        "bits": 16,
        "decode": "height_m = z_min_m + level * height_scale_m_per_level (white = high)",
    }


def _png_bytes(levels: np.ndarray, spacing: float, note: str) -> bytes:
    _require("PIL", "PNG")
    from PIL import Image, PngImagePlugin

    info = PngImagePlugin.PngInfo()
    info.add_text("metainterface", note)
    dpi = 0.0254 / spacing
    buf = io.BytesIO()
    Image.fromarray(levels).save(buf, format="PNG", pnginfo=info, dpi=(dpi, dpi))
    return buf.getvalue()


def _tiff_bytes(levels: np.ndarray, spacing: float, note: str) -> bytes:
    tifffile = _require("tifffile", "TIFF")
    per_cm = 0.01 / spacing
    buf = io.BytesIO()
    tifffile.imwrite(
        buf,
        levels,
        photometric="minisblack",
        resolution=(per_cm, per_cm),
        resolutionunit="CENTIMETER",
        description=note,
        metadata=None,
    )
    return buf.getvalue()


def _stl_bytes(mesh: Any) -> bytes:
    from trimesh.exchange.stl import export_stl

    from metainterface import __version__

    data = bytearray(export_stl(mesh))
    header = f"metainterface {__version__} binary STL, units mm".encode("ascii")
    data[:80] = header[:80].ljust(80, b"\0")
    return bytes(data)


def export_design(
    design: Design,
    out: str | os.PathLike[str],
    *,
    radius: float,
    tiles: tuple[int, int] = (1, 1),
    fmt: str | None = None,
    resolution: float | None = None,
    base: float = 1e-3,
    source: str | None = None,
    z_step: float | None = None,
    flank_step: int = FLANK_STEP,
    force: bool = False,
) -> dict[str, Any]:
    """Write the design's surface to ``out`` (and ``out.json``); returns the sidecar record.

    radius: R [m]; tiles: (nx, ny); fmt: stl|png|tiff|npy (default from the suffix);
    resolution: grid points per mm (default 64 per asperity pitch); base: STL plate
    thickness [m]; source: the design file name, for the record; z_step: a printer's layer
    height [units of R]: the asperities' height offsets are snapped to its multiples first
    (the largest shift is recorded; a design made with the same z_step moves by 0).
    flank_step: STL only, mesh the flanks between contact zones on every flank_step-th grid
    line (1: all). force: write a file over LARGE_FILE_BYTES; without it such an export
    raises an error stating the size and how to make it smaller, writing nothing.
    """
    out = Path(out)
    snap = None
    if z_step is not None:
        design, snap = _snap(design, z_step, radius)
    fmt = format_for(out, fmt)
    tiles = parse_tiles(tiles)
    grid = None if resolution is None else grid_for_resolution(design, radius, resolution)
    patch = height_patch(design, radius=radius, tiles=tiles, grid=grid)
    if not np.isfinite(patch.heights).all() or not np.isfinite(patch.spacing) or patch.spacing <= 0:
        raise MetainterfaceError("the height map is not finite; check --radius and the heights")
    expected = file_bytes(patch, fmt, flank_step)
    if expected > LARGE_FILE_BYTES and not force:
        raise MetainterfaceError(_too_large(patch, fmt, flank_step, expected))
    size = patch.size
    record: dict[str, Any] = {
        "file": out.name,
        "format": fmt,
        "radius_m": float(radius),
        "tiles": list(patch.tiles),
        "grid_per_cell": patch.grid,
        "pixel_size_m": patch.spacing,
        "points_per_mm": 1e-3 / patch.spacing,
        "cell_side_m": patch.cell_side,
        "size_m": [size[0], size[1]],
        "layout": "row i at y = i * pixel_size_m, column j at x = j * pixel_size_m; tips up",
        "cells": patch.tiles[0] * patch.tiles[1],
        "one_cell": f"{patch.cell_side * 1e3:.4g} mm square, {patch.n_side**2} asperities",
    }
    if snap is not None:
        record["z_step"] = snap
    if fmt == "npy":
        buf = io.BytesIO()
        np.save(buf, patch.heights)
        write_bytes(out, buf.getvalue())
        record["values"] = "height z [m], highest tip at 0, float64"
    elif fmt in ("png", "tiff"):
        levels, scale = _quantise(patch.heights)
        record.update(scale)
        note = json.dumps({k: record[k] for k in ("pixel_size_m", *scale)}, default=str)
        data = (_png_bytes if fmt == "png" else _tiff_bytes)(levels, patch.spacing, note)
        write_bytes(out, data)
    else:
        mesh = patch_mesh(patch, base, flank_step)
        record["flank_step"] = int(flank_step)
        write_bytes(out, _stl_bytes(mesh))
        extents = [float(v) for v in mesh.extents]
        record.update(
            units="mm",
            base_m=float(base),
            extents_mm=extents,
            relief_m=float(patch.heights.max() - patch.heights.min()),
            triangles=len(mesh.faces),
            watertight=True,
        )
    record["provenance"] = provenance(
        command="export",
        design=source,
        gamma=[float(g) for g in design.gamma],
        h=[float(v) for v in design.h],
        cell=design.settings.to_dict(),
        radius_m=float(radius),
        tiles=list(tiles),
        format=fmt,
        resolution=resolution,
        base_m=float(base) if fmt == "stl" else None,
        z_step=z_step,
    )
    write_text(sidecar_path(out), strict_json.dumps(record, indent=2) + "\n")
    return record


def _mb(n: float) -> str:
    return f"{n / 1e6:.3g} MB"


def _too_large(patch: Patch, fmt: str, flank_step: int, size: int) -> str:
    """One line: the file's size, and what would make it smaller."""
    tiles = f"{patch.tiles[0]}x{patch.tiles[1]} cells"
    ways = ["a lower --resolution"]
    if fmt == "stl":
        lx, ly = mesh_lines(patch, flank_step)
        what = f"a {_mb(size)} STL ({stl_triangles(lx.size, ly.size) / 1e6:.3g} M triangles)"
        ways.append(f"a larger --flank-step (now {flank_step})")
        ways.append(
            f"a 16-bit PNG height map (--format png, at most {_mb(file_bytes(patch, 'png'))})"
        )
    else:
        what = f"a {_mb(size)} {fmt.upper()}"
        if fmt == "npy":
            ways.append(f"a 16-bit PNG (--format png, at most {_mb(file_bytes(patch, 'png'))})")
    if patch.tiles != (1, 1):
        ways.append("fewer --tiles (the cells repeat: one cell can be tiled by the printer)")
    return (
        f"{tiles} would make {what}, above {_mb(LARGE_FILE_BYTES)}: make it smaller with "
        f"{', '.join(ways)}; or give --force (force=True) to write it"
    )


def _snap(design: Design, step: float, radius: float) -> tuple[Design, dict[str, Any]]:
    """The design with its height offsets (anchored at 0) on multiples of ``step`` [R]."""
    from dataclasses import replace

    h = design.h - design.h.min()
    snapped = np.round(h / step) * step
    scale = _scale(design, radius)
    record = {
        "z_step_m": step * scale,
        "levels": [int(v) for v in np.round(h / step)],
        "largest_shift_m": float(np.abs(snapped - h).max() * scale),
    }
    return replace(design, h=snapped), record


def sidecar_path(out: str | os.PathLike[str]) -> Path:
    """The JSON written beside an export: ``patch.png`` -> ``patch.png.json``."""
    out = Path(out)
    return out.with_name(out.name + ".json")
