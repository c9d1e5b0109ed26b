"""Designs made printable: heights snapped to a printer's layer grid, then the shape
exponents re-refined with the heights held (all targets in one batch)."""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import replace

import numpy as np
import torch
from torch import Tensor

from metainterface.inverse.designed import DesignResult
from metainterface.inverse.losses import TargetGrid, relative_error, robust_error
from metainterface.inverse.params import DTYPE, FixedHeights, snap_heights
from metainterface.inverse.perturb import Perturbation
from metainterface.inverse.refine import RefineSettings, polish
from metainterface.physics.cell import CellSettings
from metainterface.physics.models import ForwardModel


def printable(
    results: list[DesignResult],
    step: float,
    rs: RefineSettings,
    extra_loss: Callable[[Tensor, Tensor, CellSettings], Tensor] | None,
    model: ForwardModel,
    perturb: Perturbation | None = None,
    device: torch.device | None = None,
) -> list[DesignResult]:
    """The designs with heights on multiples of ``step`` [units of R] and their gammas
    re-refined (all targets in one batch, on ``device``, default the CPU); the better of
    the snapped and the re-refined design is kept, by the robust error when ``perturb`` is
    given."""
    t0 = time.perf_counter()
    dev = device or torch.device("cpu")
    settings = results[0].settings
    grid = TargetGrid.from_curves(
        [(r.target.p_star, r.target.alpha) for r in results], rs.grid_points
    ).to(dev)
    gamma = torch.as_tensor(np.array([r.gamma for r in results]), dtype=DTYPE, device=dev)
    h = torch.as_tensor(np.array([r.h for r in results]), dtype=DTYPE, device=dev)
    h = snap_heights(h, step)
    if perturb is not None:
        perturb = perturb.to(dev)
    param = FixedHeights(h=h)
    snapped = relative_error(gamma, h, settings, grid, model)
    raw = polish(
        param.from_design(gamma, h, settings), settings, grid, rs, param, extra_loss, model, perturb
    )
    g_new, _ = param.to_design(raw, settings)
    after = relative_error(g_new, h, settings, grid, model)
    if perturb is None:
        score_old, score_new = snapped, after
    else:
        score_old = robust_error(gamma, h, settings, grid, perturb, model)
        score_new = robust_error(g_new, h, settings, grid, perturb, model)
    better = score_new < score_old
    g_best = torch.where(better[:, None], g_new, gamma)
    err = torch.where(better, after, snapped)
    rob = torch.where(better, score_new, score_old) if perturb is not None else None
    # one copy to the host for all targets (it waits for the device)
    g_best, h, err, snapped = g_best.cpu(), h.cpu(), err.cpu(), snapped.cpu()
    rob = None if rob is None else rob.cpu()
    extra = (time.perf_counter() - t0) / len(results)
    out = []
    for i, r in enumerate(results):
        q = {
            "z_step": step,
            "error_before_snap": r.error,
            "error_after_snap": float(snapped[i]),
            "error_after_refine": float(err[i]),
        }
        out.append(
            replace(
                r,
                gamma=g_best[i].cpu().numpy().copy(),
                h=h[i].cpu().numpy().copy(),
                error=float(err[i]),
                robust_error=None if rob is None else float(rob[i]),
                quantisation=q,
                seconds=r.seconds + extra,
            )
        )
    return out
