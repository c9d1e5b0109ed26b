"""The made part's friction law: the BEM on its measured cell, as measured, against the
design's target; the forward model with the fitted asperities beside it, as a fast
companion.

The measured cell: every point of an M x M grid of the unit cell is looked up in each copy
of the cell that the scan shows (through the registered lattice, bilinearly, levelled) and
the copies are averaged: noise falls as 1 / sqrt(copies) and the cell is periodic by
construction. M is the scan's own resolution, never coarser. Points no copy shows (a
partial-cell scan, missing points) take the fitted family's surface, and their share is
reported. Nothing is smoothed that could be a real feature: what the family cannot
describe (layer steps, flat tips) is found and restored, and noise is treated only as far
as the scan's noise floor says (``measure.shapes``).

The made error is read from the BEM curve itself, at loads over the target's range, against
the target there (the package's one curve error, ``physics.metrics.curve_error``); the same
cell on a grid half as fine gives the BEM's own discretisation error beside it. Contacts
narrower than ``RESOLVED_PIXELS`` scan pixels are not resolved by the scan: the prediction
holds from the load on which they carry at most ``UNRESOLVED_SHARE`` of the contact area.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np
import torch

from metainterface._threads import uses_threads
from metainterface.measure.fit import levelled
from metainterface.measure.register import Registration
from metainterface.measure.scan import Scan
from metainterface.measure.shapes import Shapes, analyse, restore
from metainterface.measure.surface import lattice_surface
from metainterface.physics.cell import Design
from metainterface.physics.grid_error import grid_curve_error
from metainterface.physics.metrics import curve_error
from metainterface.physics.registry import get_model
from metainterface.validation import owner_map, solve_path

#: BEM grid points per scan pixel (``default_grid``).
GRID_PER_PIXEL = 2.0
#: Where BEM and fitted model differ by more than this, the fitted family misses a shape.
DISAGREE = 0.03
#: A contact narrower (in diameter) than this many scan pixels is not resolved by the scan.
RESOLVED_PIXELS = 4.0
#: The prediction holds where unresolved contacts carry at most this share of the area.
UNRESOLVED_SHARE = 0.05


@dataclass(frozen=True)
class MeasuredCell:
    """heights: (M, M) the measured unit cell [R], tips up, in the registration's height
    frame (made tips at -h); fitted: (M, M) the fitted family's surface there; spacing:
    L / M [R]; copies: (M, M) number of cell copies averaged at each point; filled: share
    of the points no copy showed (taken from the fitted surface)."""

    heights: np.ndarray
    fitted: np.ndarray
    spacing: float
    copies: np.ndarray
    filled: float


def measured_cell(scan: Scan, reg: Registration, design: Design, grid: int) -> MeasuredCell:
    """The phase-averaged measured cell on a grid x grid grid (module docstring)."""
    from scipy import ndimage

    s = design.settings
    side = s.cell_side
    spacing = side / grid
    u, v = np.meshgrid(np.arange(grid) * spacing, np.arange(grid) * spacing)
    z = levelled(scan, reg.tilt)
    ok = np.isfinite(z)
    zf = np.where(ok, z, 0.0)
    width, height = scan.size
    cu, cv = reg.lattice.to_cell(np.array([0, width, 0, width]), np.array([0, 0, height, height]))
    okf = ok.astype(float)
    total = np.zeros_like(u)
    count = np.zeros_like(u)
    for cy in range(math.floor(cv.min() / side) - 1, math.ceil(cv.max() / side) + 1):
        for cx in range(math.floor(cu.min() / side) - 1, math.ceil(cu.max() / side) + 1):
            x, y = reg.lattice.to_scan(u + cx * side, v + cy * side)
            row, col = y / scan.dy, x / scan.dx
            inside = (row >= 0) & (row <= scan.shape[0] - 1)
            inside &= (col >= 0) & (col <= scan.shape[1] - 1)
            if not inside.any():
                continue
            # only the points this copy shows are looked up (most of the grid lies outside)
            coords = np.stack([row[inside], col[inside]])
            w = ndimage.map_coordinates(okf, coords, order=1, mode="nearest")
            val = ndimage.map_coordinates(zf, coords, order=1, mode="nearest")
            good = w > 0.999  # all four neighbours measured
            use = np.zeros_like(inside)
            use[inside] = good
            total[use] += val[good] / w[good]
            count[use] += 1
    fitted = lattice_surface(u, v, -reg.h, reg.gamma, s)
    seen = count > 0
    heights = fitted.copy()
    if seen.any():
        # onto the made heights' frame by the registration's own offset (not by a median
        # against the fitted surface: cut tips and layers would bias that)
        heights[seen] = total[seen] / count[seen] + reg.level
    return MeasuredCell(
        heights=heights, fitted=fitted, spacing=spacing, copies=count, filled=float(1 - seen.mean())
    )


def shapes_of(
    scan: Scan,
    reg: Registration,
    design: Design,
    grid: int | None = None,
    z_step: float | None = None,
) -> tuple[MeasuredCell, Shapes]:
    """The measured cell on ``grid`` (default ``default_grid``) and what it shows beyond the
    fitted family (``measure.shapes.analyse``), before any restoration."""
    grid = default_grid(scan, design) if grid is None else grid
    raw = measured_cell(scan, reg, design, grid)
    owner = owner_map(design.settings.n_side, grid)
    shapes = analyse(raw.heights, raw.fitted, owner, scan, raw.copies, design, reg.gamma, z_step)
    return raw, shapes


def default_grid(scan: Scan, design: Design) -> int:
    """M for the measured cell: twice the scan's own resolution per cell (its finer axis),
    rounded up to a multiple of n, between 64 n and 256 n points. Never coarser than the
    scan; twice as fine because restored layer steps are sharper than the scan's pixels and
    a BEM on the scan's own grid reads a terraced cell's area 2-5 % high where twice as
    fine reads it within 1.2 % (tests/measure/test_printed.py holds it to 4 %)."""
    n = design.settings.n_side
    per_cell = design.settings.cell_side / min(scan.dx, scan.dy)
    m = math.ceil(GRID_PER_PIXEL * per_cell / n - 1e-9) * n
    return int(min(max(m, 64 * n), 256 * n))


def target_of(design: Design, model: Any = None) -> tuple[np.ndarray, np.ndarray]:
    """The design file's target (p_star, alpha), or the design's own model curve (its
    promise) where it carries none."""
    from metainterface.validation import design_target

    target = design_target(design)
    if target is not None:
        return target
    gamma, h = design.tensors()
    with torch.no_grad():
        sw = get_model(model).sweep(gamma, h, design.settings)
    return sw.p_star[0].numpy(), sw.alpha[0].numpy()


def model_alpha(
    gamma: np.ndarray, h: np.ndarray, design: Design, p_star: np.ndarray, model: Any = None
) -> tuple[np.ndarray, np.ndarray]:
    """alpha (B, K) of the cells (gamma, h) (B, N) [h in R] at pressures p_star (K,), and
    their P*_max (B,), by the forward model (exact). Rows may leave the design's gamma
    bounds (a made part does); the cell (L, A_nom) stays the design's."""
    g = torch.as_tensor(np.atleast_2d(np.asarray(gamma, dtype=np.float64)))
    hh = torch.as_tensor(np.atleast_2d(np.asarray(h, dtype=np.float64)))
    p = torch.as_tensor(np.asarray(p_star, dtype=np.float64))[None].expand(g.shape[0], -1)
    with torch.no_grad():
        alpha, p_max = get_model(model).alpha_at(g, hh, design.settings, p.contiguous(), exact=True)
    return alpha.numpy(), p_max.numpy()


def bem_error(p_star: np.ndarray, alpha: np.ndarray, target: tuple[np.ndarray, np.ndarray]):
    """The curve error of a BEM curve alpha (..., K) at its loads p_star (K,) against the
    target read at those loads (a BEM cell reaches every load: coverage 1)."""
    ref = np.interp(p_star, target[0], target[1], left=0.0)
    a = np.atleast_2d(alpha)
    ones = np.ones_like(a)
    err = curve_error(a, ref * ones, p_star * ones, np.full(len(a), np.inf))
    return np.asarray(err)


def loads_over(target: tuple[np.ndarray, np.ndarray], loads: int) -> np.ndarray:
    """K loads, uniform up to the target's largest [P*]."""
    return float(target[0][-1]) * np.arange(1, loads + 1) / loads


def coarse_grid(grid: int, n: int) -> int:
    """The second grid of the discretisation estimate: half as fine, a multiple of n."""
    return max(16 * n, round(grid / 2 / n) * n)


def resolved_from(
    p_star: np.ndarray, asperity_alpha: np.ndarray, cell_side: float, pixel: float
) -> float | None:
    """The lowest load [P*] from which on contacts narrower than RESOLVED_PIXELS scan
    pixels carry at most UNRESOLVED_SHARE of the contact area (None: at no load)."""
    area = asperity_alpha * cell_side**2
    diameter = 2.0 * np.sqrt(area / math.pi)
    small = (area > 0) & (diameter < RESOLVED_PIXELS * pixel)
    share = (area * small).sum(axis=1) / np.maximum(area.sum(axis=1), 1e-300)
    ok = share <= UNRESOLVED_SHARE
    bad = np.flatnonzero(~ok)
    if bad.size == 0:
        return float(p_star[0])
    if bad[-1] == len(p_star) - 1:
        return None
    return float(p_star[bad[-1] + 1])


@dataclass(frozen=True)
class Prediction:
    """The made part's law.

    p_star: (K,) BEM loads over the target's range; alpha_bem: (K,) the BEM on the measured
    cell (restored: ``shapes``); alpha_coarse: (K,) the same on the coarse grid;
    alpha_target: (K,) the target there; alpha_fit, alpha_design: (K,) the forward model
    with the fitted asperities, and the design's. error_bem: the made error, from the BEM
    curve at its loads; error_accuracy: the BEM's own discretisation error on that figure
    (its difference from the coarse grid's); error_fit, error_design, coverage_fit: the
    forward model's curve errors. grid, grid_coarse: the BEM grids. resolved_from: the load
    [P*] from which on the scan resolves the contacts (None: nowhere). disagree: (K,) bool,
    where abs(alpha_bem / alpha_fit - 1) > DISAGREE. cell: the measured cell solved
    (``heights`` as restored). shapes: what the family cannot describe. share: (N,) each
    asperity's share of the made curve error (the error of the design with that asperity
    alone made as measured, normalised); error_alone: (N,) those errors.
    """

    p_star: np.ndarray
    alpha_bem: np.ndarray
    alpha_coarse: np.ndarray
    alpha_target: np.ndarray
    alpha_fit: np.ndarray
    alpha_design: np.ndarray
    error_bem: float
    error_accuracy: float
    error_fit: float
    error_design: float
    coverage_fit: float
    grid: int
    grid_coarse: int
    resolved_from: float | None
    disagree: np.ndarray
    cell: MeasuredCell
    shapes: Shapes
    share: np.ndarray
    error_alone: np.ndarray
    target: tuple[np.ndarray, np.ndarray]
    adhesion: float = 0.0


def solve_cell(
    heights: np.ndarray,
    design: Design,
    p_star: np.ndarray,
    *,
    engine: Any = None,
    device: Any = "auto",
    report: Callable[[int], Any] | None = None,
):
    """The BEM load path (``validation.LoadPath``) of a cell (M, M) [R], tips up."""
    s = design.settings
    m = heights.shape[0]
    return solve_path(
        heights - heights.max(),
        s.cell_side,
        p_star,
        owner_map(s.n_side, m),
        s.n_asperities,
        engine=engine,
        device=device,
        threads=None,
        report=report,
    )


@uses_threads()
def predict(
    scan: Scan,
    reg: Registration,
    design: Design,
    *,
    grid: int | None = None,
    loads: int = 8,
    model: Any = None,
    report: Callable[[int], Any] | None = None,
    engine: Any = None,
    device: Any = "auto",
    z_step: float | None = None,
    adhesion: float = 0.0,
) -> Prediction:
    """BEM of the measured cell (and of it on a grid half as fine), the fitted model beside
    it, against the design's target (module docstring).

    grid: M of the measured cell (default ``default_grid``); loads: K BEM loads, uniform up
    to the target's largest; model: the forward model; report: called with 1 after each
    load of either grid; engine, device: the BEM's (``solve_path``); z_step: the printer's
    layer step [R] where known (else read from the scan). adhesion: the work of adhesion
    [E* R] of an adhesive part: the cell is then solved in the JKR-limit BEM by approach,
    its loading curve the states a rising force reaches (``adhesive_path.jkr_path``), and
    the fitted model is the adhesive one."""
    s = design.settings
    if adhesion > 0:
        model = get_model(model).with_adhesion(adhesion)
    target = target_of(design, model)
    grid = default_grid(scan, design) if grid is None else grid
    grid2 = coarse_grid(grid, s.n_side)
    raw, shapes = shapes_of(scan, reg, design, grid, z_step)
    owner = owner_map(s.n_side, grid)
    cell = restore(raw.heights, owner, shapes)
    raw2 = measured_cell(scan, reg, design, grid2)
    cell2 = restore(raw2.heights, owner_map(s.n_side, grid2), shapes)
    p = loads_over(target, loads)
    if adhesion > 0:
        depth = _approach_depth(reg, design, model, float(p[-1]))
        alpha1 = adhesive_alpha(cell, design, p, adhesion, depth, device=device, report=report)
        alpha2 = adhesive_alpha(cell2, design, p, adhesion, depth, device=device, report=report)
        resolved = None  # the adhesive path keeps no per-asperity areas
    else:
        path = solve_cell(cell, design, p, engine=engine, device=device, report=report)
        path2 = solve_cell(cell2, design, p, engine=engine, device=device, report=report)
        alpha1, alpha2 = path.alpha, path2.alpha
        resolved = resolved_from(p, path.asperity_alpha, s.cell_side, max(scan.dx, scan.dy))
    errs_bem = bem_error(p, np.stack([alpha1, alpha2]), target)
    h_design = design.h - design.h.min()
    both, _ = model_alpha(
        np.stack([reg.gamma, design.gamma]), np.stack([reg.h, h_design]), design, p, model
    )
    alpha_fit, alpha_design = both
    errs, cover = grid_curve_error(
        np.stack([reg.gamma, design.gamma]),
        np.stack([reg.h, h_design]),
        design.settings,
        target,
        model,
    )
    n = s.n_asperities
    g_alone = np.tile(design.gamma, (n, 1))
    h_alone = np.tile(h_design, (n, 1))
    g_alone[np.arange(n), np.arange(n)] = reg.gamma
    h_alone[np.arange(n), np.arange(n)] = reg.h
    alone, _ = grid_curve_error(g_alone, h_alone, design.settings, target, model)
    excess = np.maximum(alone - errs[1], 0.0)
    share = excess / excess.sum() if excess.sum() > 0 else np.zeros(n)
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = np.where(alpha_fit > 0, alpha1 / alpha_fit, np.inf)
    return Prediction(
        p_star=p,
        alpha_bem=alpha1,
        alpha_coarse=alpha2,
        alpha_target=np.interp(p, target[0], target[1], left=0.0),
        alpha_fit=alpha_fit,
        alpha_design=alpha_design,
        error_bem=float(errs_bem[0]),
        error_accuracy=float(abs(errs_bem[0] - errs_bem[1])),
        error_fit=float(errs[0]),
        error_design=float(errs[1]),
        coverage_fit=float(cover[0]),
        grid=grid,
        grid_coarse=grid2,
        resolved_from=resolved,
        adhesion=adhesion,
        disagree=np.abs(ratio - 1.0) > DISAGREE,
        cell=MeasuredCell(
            heights=cell,
            fitted=raw.fitted,
            spacing=raw.spacing,
            copies=raw.copies,
            filled=raw.filled,
        ),
        shapes=shapes,
        share=share,
        error_alone=alone,
        target=target,
    )


#: Approaches of the adhesive path per load asked for (states off the rising branch, just
#: after a snap-in, are dropped).
APPROACHES_PER_LOAD = 3


def _approach_depth(reg: Registration, design: Design, model: Any, top: float) -> float:
    """The approach [R] at which the fitted adhesive model's loading curve reaches ``top``,
    and a quarter more (the BEM's cell may need it), at most 2 Delta_max."""
    s = design.settings
    g = torch.as_tensor(reg.gamma[None].astype(np.float64))
    h = torch.as_tensor(reg.h[None].astype(np.float64))
    with torch.no_grad():
        sw = get_model(model).sweep(g, h, s)
    delta = (sw.delta[0] if sw.delta.dim() == 2 else sw.delta).numpy()
    reach = np.flatnonzero(sw.p_star[0].numpy() >= top)
    end = float(delta[reach[0]]) if reach.size else float(delta[-1])
    return min(2.0 * s.delta_max, 1.25 * end)


def adhesive_alpha(
    cell: np.ndarray,
    design: Design,
    p_star: np.ndarray,
    adhesion: float,
    depth: float,
    *,
    device: Any = "auto",
    report: Callable[[int], Any] | None = None,
) -> np.ndarray:
    """alpha (K,) of an adhesive cell (M, M) [R] at loads p_star (K,) under a rising force:
    the JKR-limit BEM by approach up to ``depth`` [R], the states on the rising-force branch,
    read at the loads (held beyond them). adhesion: w [E* R]."""
    from metainterface._device import resolve_device
    from metainterface.validation.adhesive_path import jkr_path

    s = design.settings
    k = APPROACHES_PER_LOAD * len(p_star)
    approaches = depth * np.arange(1, k + 1) / k
    path = jkr_path(
        cell - cell.max(),
        s.cell_side,
        adhesion * s.e_star * s.radius,
        approaches,
        device=resolve_device(device),
    )
    if report is not None:
        report(len(p_star))
    keep = path.on_branch
    if keep.sum() < 2:
        from metainterface.errors import MetainterfaceError

        raise MetainterfaceError(
            "the adhesive BEM of the measured cell reached too few loads under a rising force"
        )
    order = np.argsort(path.p_star[keep])
    return np.interp(p_star, path.p_star[keep][order], path.alpha[keep][order])
