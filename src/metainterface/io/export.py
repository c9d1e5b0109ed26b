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
height scale, the grid, the tiling and the provenance. The patch is built in
``metainterface.io.patch``, the STL mesh in ``metainterface.io.stl``.
"""

from __future__ import annotations

import io
import json
import os
from pathlib import Path
from typing import Any

import numpy as np

from metainterface._files import strict_json
from metainterface._files.atomic import write_bytes, write_text
from metainterface._files.provenance import provenance
from metainterface._names import EXPORT_FORMATS
from metainterface.errors import MetainterfaceError
from metainterface.io._optional import require
from metainterface.io.patch import (
    Patch,
    grid_for_resolution,
    height_patch,
    length_scale,
    parse_tiles,
)
from metainterface.io.stl import (
    FLANK_STEP,
    mesh_lines,
    patch_mesh,
    stl_bytes,
    stl_triangles,
)
from metainterface.physics.cell import Design

FORMATS = EXPORT_FORMATS
SUFFIXES = {".stl": "stl", ".png": "png", ".tif": "tiff", ".tiff": "tiff", ".npy": "npy"}
_LEVELS = 65535
#: Files larger than this [bytes] are written only when asked (``force``): the size is
#: stated first, with ways to make the file smaller.
LARGE_FILE_BYTES = 100 * 10**6


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


def file_bytes(patch: Patch, fmt: str, flank_step: int = 1) -> int:
    """The size of the export [bytes] (at most, for the compressed PNG)."""
    ny, nx = patch.heights.shape
    if fmt == "stl":
        lx, ly = mesh_lines(patch, flank_step)
        return 84 + 50 * stl_triangles(lx.size, ly.size)
    return nx * ny * (8 if fmt == "npy" else 2) + 1024


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
    require("PIL", "PNG")
    from PIL import Image, PngImagePlugin

    info = PngImagePlugin.PngInfo()
    info.add_text("metainterface", note)
    dpi = 0.0254 / spacing
    buf = io.BytesIO()
    Image.fromarray(levels).save(buf, format="PNG", pnginfo=info, dpi=(dpi, dpi))
    return buf.getvalue()


def _tiff_bytes(levels: np.ndarray, spacing: float, note: str) -> bytes:
    tifffile = require("tifffile", "TIFF")
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
        write_bytes(out, stl_bytes(mesh))
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
    scale = length_scale(design, radius)
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
