"""The made part's friction law: the BEM on its measured cell, and the forward model with
its fitted asperities, against the design's target.

The measured cell: every point of an M x M grid of the unit cell is looked up in each copy
of the cell that the scan shows (through the registered lattice, bilinearly, levelled) and
the copies are averaged: noise falls as 1 / sqrt(copies) and the cell is periodic by
construction. Points no copy shows (a partial-cell scan, missing points) take the fitted
family's surface, and their share is reported; a Gaussian of half a grid step takes the
instrument's pixel noise off (``SMOOTH``). The error is the package's one curve error
(``physics.metrics.curve_error``) on the target's grid, with coverage.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np
import torch

from metainterface.measure.fit import levelled
from metainterface.measure.register import Registration
from metainterface.measure.scan import Scan
from metainterface.measure.surface import lattice_surface
from metainterface.physics.cell import Design
from metainterface.physics.metrics import curve_error
from metainterface.physics.registry import get_model
from metainterface.validation import owner_map, solve_path

#: Points of the uniform grid every curve error is measured on (as ``validation``'s).
ERROR_POINTS = 128
#: Gaussian smoothing of the measured cell [grid steps]: half a step takes most of a
#: scan's pixel noise off (0.1 um at R = 0.5 mm read the first contacts' area 1.8 % low on
#: a 255^2 cell, 0.8 % with it; benchmarks/bench_measure.py) and leaves the tips' shapes.
SMOOTH = 0.5
#: Where BEM and fitted model differ by more than this, the fitted family misses a shape.
DISAGREE = 0.03


@dataclass(frozen=True)
class MeasuredCell:
    """heights: (M, M) the measured unit cell [R], tips up, highest point 0; spacing: L / M
    [R]; copies: (M, M) number of cell copies averaged at each point; filled: share of the
    points no copy showed (taken from the fitted surface)."""

    heights: np.ndarray
    spacing: float
    copies: np.ndarray
    filled: float


def measured_cell(
    scan: Scan, reg: Registration, design: Design, grid: int, smooth: float = 0.0
) -> MeasuredCell:
    """The phase-averaged measured cell on a grid x grid grid (module docstring), smoothed
    by a Gaussian of ``smooth`` grid steps (0: not at all)."""
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
    total = np.zeros_like(u)
    count = np.zeros_like(u)
    for cy in range(math.floor(cv.min() / side) - 1, math.ceil(cv.max() / side) + 1):
        for cx in range(math.floor(cu.min() / side) - 1, math.ceil(cu.max() / side) + 1):
            x, y = reg.lattice.to_scan(u + cx * side, v + cy * side)
            coords = np.stack([y / scan.dy, x / scan.dx])
            inside = (coords[0] >= 0) & (coords[0] <= scan.shape[0] - 1)
            inside &= (coords[1] >= 0) & (coords[1] <= scan.shape[1] - 1)
            if not inside.any():
                continue
            w = ndimage.map_coordinates(ok.astype(float), coords, order=1, mode="nearest")
            val = ndimage.map_coordinates(zf, coords, order=1, mode="nearest")
            use = inside & (w > 0.999)  # all four neighbours measured
            total[use] += val[use] / w[use]
            count[use] += 1
    fitted = lattice_surface(u, v, -reg.h, reg.gamma, s)
    seen = count > 0
    heights = fitted.copy()
    if seen.any():
        mean = total[seen] / count[seen]
        heights[seen] = mean - np.median(mean - fitted[seen])  # onto the fitted level
    if smooth > 0:  # the instrument's noise off (periodic), the shapes kept
        heights = ndimage.gaussian_filter(heights, smooth, mode="wrap")
    heights -= heights.max()
    return MeasuredCell(
        heights=heights + 0.0, spacing=spacing, copies=count, filled=float(1 - seen.mean())
    )


def default_grid(scan: Scan, design: Design) -> int:
    """M for the measured cell: the scan's own resolution per cell (its finer axis), a
    multiple of n, between 64 n and 256 n points."""
    n = design.settings.n_side
    per_cell = design.settings.cell_side / min(scan.dx, scan.dy)
    m = round(per_cell / n) * n
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


def curve_errors(
    gamma: np.ndarray,
    h: np.ndarray,
    design: Design,
    target: tuple[np.ndarray, np.ndarray],
    model: Any = None,
    ratio: tuple[np.ndarray, np.ndarray] | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """(error (B,), coverage (B,)) of the cells (gamma, h) (B, N) against ``target``, on its
    ERROR_POINTS grid. ratio: (loads (K,), alpha_bem / alpha_model (K,)) multiplies the
    model's alpha, interpolated (held at the ends): the BEM's error, as ``validate``'s."""
    p_t, a_t = target
    grid = np.linspace(0.0, float(p_t[-1]), ERROR_POINTS)
    ref = np.interp(grid, p_t, a_t, left=0.0)
    alpha, p_max = model_alpha(gamma, h, design, grid, model)
    if ratio is not None:
        alpha = alpha * np.interp(grid, ratio[0], np.nan_to_num(ratio[1], nan=1.0))
    b = alpha.shape[0]
    err = curve_error(alpha, np.tile(ref, (b, 1)), np.tile(grid, (b, 1)), p_max)
    return np.asarray(err), np.minimum(1.0, p_max / p_t[-1])


@dataclass(frozen=True)
class Prediction:
    """The made part's law.

    p_star: (K,) BEM loads; alpha_bem, alpha_fit, alpha_design: (K,) the BEM on the measured
    cell, the forward model with the fitted asperities, the design's model. error_bem,
    error_fit, error_design, coverage_*: curve errors to the target (and coverage).
    disagree: (K,) bool, where abs(alpha_bem / alpha_fit - 1) > DISAGREE. cell: the measured
    cell solved. share: (N,) each asperity's share of the made curve error (the error of
    the design with that asperity alone made as measured, normalised over the asperities).
    error_alone: (N,) those errors.
    """

    p_star: np.ndarray
    alpha_bem: np.ndarray
    alpha_fit: np.ndarray
    alpha_design: np.ndarray
    error_bem: float
    error_fit: float
    error_design: float
    coverage_fit: float
    disagree: np.ndarray
    cell: MeasuredCell
    share: np.ndarray
    error_alone: np.ndarray
    target: tuple[np.ndarray, np.ndarray]


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
    smooth: float = SMOOTH,
) -> Prediction:
    """BEM of the measured cell and the fitted model, against the design's target.

    grid: M of the measured cell (default ``default_grid``); loads: K BEM loads, uniform up
    to the made part's P*_max (or the target's largest load); model: the forward model;
    report: called with 1 after each load; engine, device: the BEM's (``solve_path``);
    smooth: the measured cell's Gaussian smoothing [grid steps]."""
    s = design.settings
    target = target_of(design, model)
    grid = default_grid(scan, design) if grid is None else grid
    cell = measured_cell(scan, reg, design, grid, smooth=smooth)
    h_design = design.h - design.h.min()
    _, p_max = model_alpha(reg.gamma, reg.h, design, target[0][-1:], model)
    top = float(min(p_max[0], target[0][-1]))
    p = top * np.arange(1, loads + 1) / loads
    path = solve_path(
        cell.heights,
        s.cell_side,
        p,
        owner_map(s.n_side, grid),
        s.n_asperities,
        engine=engine,
        device=device,
        threads=None,
        report=report,
    )
    both, _ = model_alpha(
        np.stack([reg.gamma, design.gamma]), np.stack([reg.h, h_design]), design, p, model
    )
    alpha_fit, alpha_design = both
    ratio = path.alpha / alpha_fit
    errs, cover = curve_errors(
        np.stack([reg.gamma, reg.gamma, design.gamma]),
        np.stack([reg.h, reg.h, h_design]),
        design,
        target,
        model,
    )
    err_bem, _ = curve_errors(reg.gamma[None], reg.h[None], design, target, model, (p, ratio))
    n = s.n_asperities
    g_alone = np.tile(design.gamma, (n, 1))
    h_alone = np.tile(h_design, (n, 1))
    g_alone[np.arange(n), np.arange(n)] = reg.gamma
    h_alone[np.arange(n), np.arange(n)] = reg.h
    alone, _ = curve_errors(g_alone, h_alone, design, target, model)
    excess = np.maximum(alone - errs[2], 0.0)
    share = excess / excess.sum() if excess.sum() > 0 else np.zeros(n)
    return Prediction(
        p_star=p,
        alpha_bem=path.alpha,
        alpha_fit=alpha_fit,
        alpha_design=alpha_design,
        error_bem=float(err_bem[0]),
        error_fit=float(errs[0]),
        error_design=float(errs[2]),
        coverage_fit=float(cover[0]),
        disagree=np.abs(ratio - 1.0) > DISAGREE,
        cell=cell,
        share=share,
        error_alone=alone,
        target=target,
    )
