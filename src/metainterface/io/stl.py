"""The printable STL of a height-map patch: a watertight mesh on a base plate, in
millimetres (trimesh): top grid triangles, four side walls and a bottom fan that share every
edge, checked closed before it is written."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from metainterface.errors import MetainterfaceError
from metainterface.io._optional import require
from metainterface.io.patch import Patch

#: Largest STL, to keep files and memory sane.
MAX_STL_TRIANGLES = 8_000_000
#: STL flanks: outside the contact zone of each asperity (a_max from its centre, with this
#: margin) the surface is meshed on every FLANK_STEP-th grid line only by default.
FLANK_STEP = 4
CONTACT_MARGIN = 1.15


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


def patch_mesh(patch: Patch, base: float, flank_step: int = 1) -> Any:
    """A watertight trimesh.Trimesh of the patch on a base plate, in millimetres.

    base: plate thickness under the lowest surface point [m], > 0. The bottom face is at
    z = 0, the grid spans [0, nx L R] x [0, ny L R]; the last row and column close the
    period (they repeat the first). Faces are wound outwards. flank_step: mesh the flanks
    between the asperities' contact zones on every flank_step-th grid line only
    (:func:`mesh_lines`; 1 = every line); a tensor grid, so it stays watertight.
    """
    trimesh = require("trimesh", "STL")
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


def stl_bytes(mesh: Any) -> bytes:
    from trimesh.exchange.stl import export_stl

    from metainterface import __version__

    data = bytearray(export_stl(mesh))
    header = f"metainterface {__version__} binary STL, units mm".encode("ascii")
    data[:80] = header[:80].ljust(80, b"\0")
    return bytes(data)
