"""Idle asperities put to use: a design whose asperities sit too high to touch within the
target's pressure range is refined again with them re-seeded lower.

An asperity whose tip is more than Delta_L above the lowest one, Delta_L the indentation at
which the design carries the target's largest pressure (at most Delta_max), never touches
over the law: it is printed but carries nothing, and its place on the cell is wasted. The
loss cannot bring it back by itself (its gradient is zero while it does not touch). Such a
design gets ``RESEED_STARTS`` new starts: the idle asperities moved to random heights
within Delta_L of the lowest tip and given random shape exponents, the others as designed;
they are refined like any start, and the best of those that leave fewer asperities idle
replaces the design when its error is no worse than the design's by more than
``RESEED_SLACK`` (relative) or ``RESEED_FLOOR`` (absolute): a cell whose asperities carry
load is worth a hair of curve error. Where none is good enough (a law that only a few
sharp asperities can follow), the design stays as it is and its idle asperities are
reported.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING

import numpy as np
import torch
from torch import Tensor

from metainterface.inverse.losses import TargetGrid, relative_error
from metainterface.inverse.params import FULL
from metainterface.inverse.refine import RefineSettings, polish, refine
from metainterface.physics.cell import CellSettings
from metainterface.physics.metrics import interp
from metainterface.physics.models import ForwardModel

if TYPE_CHECKING:
    from metainterface.inverse.designed import DesignResult

DTYPE = torch.float64
#: Re-seeded starts per design with idle asperities.
RESEED_STARTS = 8
#: How much worse (relative, or absolute) a re-seeded design may be and still be taken.
RESEED_SLACK = 0.1
RESEED_FLOOR = 0.002
#: Samples of the sweep that finds Delta_L.
SWEEP_POINTS = 512


def idle_in_range(
    gamma: Tensor, h: Tensor, settings: CellSettings, p_max: Tensor, model: ForwardModel
) -> tuple[Tensor, Tensor]:
    """(idle (B, N) bool, Delta_L (B,)): the asperities of (B, N) designs whose tips sit more
    than Delta_L above the lowest, Delta_L the indentation at pressure p_max (B,) (Delta_max
    where the design does not reach it)."""
    with torch.no_grad():
        sw = model.sweep(gamma, h, settings, n_delta=SWEEP_POINTS)
        delta = sw.delta if sw.delta.dim() == 2 else sw.delta.expand_as(sw.p_star)
        d_l = interp(p_max[:, None].to(sw.p_star.dtype), sw.p_star, delta)[:, 0]
        reached = sw.p_star[:, -1] >= p_max
        d_l = torch.where(reached, d_l, torch.full_like(d_l, settings.delta_max))
        rel = h - h.min(-1, keepdim=True).values
        return rel > d_l[:, None] * (1 + 1e-9), d_l


def reseed(
    results: list[DesignResult],
    refine_settings: RefineSettings,
    extra_loss: Callable[[Tensor, Tensor, CellSettings], Tensor] | None,
    model: ForwardModel,
    seed: int,
) -> list[DesignResult]:
    """The results, each design with asperities idle over its target's range replaced by a
    re-seeded, re-refined one where that is no worse (see the module docstring)."""
    if not results:
        return results
    s = results[0].settings
    gamma = torch.as_tensor(np.stack([r.gamma for r in results]), dtype=DTYPE)
    h = torch.as_tensor(np.stack([r.h for r in results]), dtype=DTYPE)
    p_max = torch.tensor([float(r.target.p_star[-1]) for r in results], dtype=DTYPE)
    idle, d_l = idle_in_range(gamma, h, s, p_max, model)
    todo = [i for i in range(len(results)) if bool(idle[i].any())]
    if not todo:
        return results
    k = RESEED_STARTS
    gen = torch.Generator().manual_seed(seed + 7)
    rows = torch.tensor(todo).repeat_interleave(k)
    g0, h0, mask = gamma[rows].clone(), h[rows].clone(), idle[rows]
    base = h0.min(-1, keepdim=True).values
    new_h = base + 0.9 * d_l[rows][:, None] * torch.rand(g0.shape, generator=gen, dtype=DTYPE)
    span = s.gamma_max - s.gamma_min
    new_g = s.gamma_min + span * torch.rand(g0.shape, generator=gen, dtype=DTYPE)
    h0 = torch.where(mask, new_h, h0)
    g0 = torch.where(mask, new_g, g0)
    grid = TargetGrid.from_curves(
        [(results[i].target.p_star, results[i].target.alpha) for i in todo],
        refine_settings.grid_points,
    ).rows(torch.arange(len(todo)).repeat_interleave(k))
    raw = FULL.from_design(g0, h0, s)
    raw = refine(raw, s, grid, refine_settings, FULL, extra_loss, model)
    if refine_settings.polish_iterations > 0:
        raw = polish(raw, s, grid, refine_settings, FULL, extra_loss, model)
    g1, h1 = FULL.to_design(raw.detach(), s)
    err = relative_error(g1, h1, s, grid, model).view(len(todo), k)
    still, _ = idle_in_range(g1, h1, s, p_max[rows], model)
    left = still.sum(-1).view(len(todo), k)
    fewer = left < idle[todo].sum(-1, keepdim=True)
    err = torch.where(fewer, err, torch.inf)  # it must put at least one of them to use
    out = list(results)
    for j, i in enumerate(todo):
        b = int(err[j].argmin())
        e = float(err[j, b])
        r = results[i]
        if e <= max(r.error * (1 + RESEED_SLACK), r.error + RESEED_FLOOR):
            row = j * k + b
            n_idle = int(idle[i].sum())
            note = (
                f"target {r.target.name}: {_count(n_idle)} that never touched over the "
                f"target's range {'was' if n_idle == 1 else 'were'} re-seeded, "
                f"{_count(int(left[j, b]))} idle now (error {100 * r.error:.3g} % -> "
                f"{100 * e:.3g} %)"
            )
            out[i] = r.redesigned(g1[row].numpy(), h1[row].numpy(), e, note)
    return out


def _count(n: int) -> str:
    return "1 asperity" if n == 1 else f"{n} asperities"
