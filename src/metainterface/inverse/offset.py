"""An offset law's friction at zero load: a last polish that weighs it (issue 38).

An adhesive cell holds contact at zero load (its asperities snap in at touch), so a friction
law made with adhesion may start at F_f(0) = F_0 > 0: what a gripper or a haptic part is
often specified by. The curve error weighs that point as one of the target's 128 pressures,
and F_0 is set mostly by how many asperities are in contact at zero load (those whose tips
sit below the zero-load indentation Delta_0): a count, which no gradient changes. Designs
met the curve and missed F_0 by 13 % (median) and far more on some laws.

So a design of an adhesive target with F_0 > 0, unless it is within ``F0_TOL`` of F_0
already, gets a last polish (Levenberg-Marquardt on
the exact law, as the pipeline's) with the zero-load point weighted ``OFFSET_WEIGHT`` times,
from the design itself and from copies of it with one or two asperities more or fewer in
contact at zero load (the next tips lowered below Delta_0, or the last ones lifted above
it). Of the polished designs whose curve error is within ``OFFSET_SLACK`` (relative) or
``OFFSET_FLOOR`` (absolute) of the design's, the one nearest F_0 (any within ``F0_TOL`` as near as
another, the smaller curve error then) replaces it if better so than the design; a note says
so. ``benchmarks/bench_offset_f0.py`` measures it.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import replace
from typing import TYPE_CHECKING

import numpy as np
import torch
from torch import Tensor

from metainterface.inverse.losses import TargetGrid
from metainterface.inverse.params import FULL
from metainterface.inverse.refine import RefineSettings, polish
from metainterface.physics.cell import CellSettings
from metainterface.physics.curves import anchor
from metainterface.physics.metrics import curve_error
from metainterface.physics.models import ZERO_LOAD, ForwardModel
from metainterface.physics.pressures import solve_delta

if TYPE_CHECKING:
    from metainterface.inverse.designed import DesignResult
    from metainterface.inverse.targets import Target

DTYPE = torch.float64
#: The zero-load point's weight in the offset polish, relative to each other point's.
OFFSET_WEIGHT = 256.0
#: How much worse (relative, or absolute) the curve error may get for a nearer F_0.
OFFSET_SLACK = 0.1
OFFSET_FLOOR = 0.001
#: An F_0 this near the law's (relative) counts as met: the curve error then decides.
F0_TOL = 0.01
#: What a design of an offset law meets (issue 52): F_0 within 2 % of the law's, beside
#: the curve within 2 %. The polish may trade curve error up to ``CURVE_MEET`` for F_0 (a
#: gripper is specified by its friction at zero load more than by any other point), and a
#: design whose F_0 is further off says so in its summary and exit status.
F0_MEET = 0.02
CURVE_MEET = 0.02
#: The contact counts tried: the design's own and up to this many more or fewer.
COUNT_STEPS = 2


def extrapolated(target: Target) -> bool:
    """Whether the target's F_0 was extrapolated from its law's first two rows (a law that
    begins above zero load; ``meta["friction"]["offset"]``), not given."""
    law = target.meta.get("friction", {}) if isinstance(target.meta, dict) else {}
    return law.get("offset") == "extrapolated"


def has_offset(result: DesignResult) -> bool:
    """Whether the result's target starts at zero load with friction (F_0 > 0) that its
    law gives (not :func:`extrapolated`)."""
    t = result.target
    return bool(t.p_star.size and t.p_star[0] == 0 and t.alpha[0] > 0 and not extrapolated(t))


def contact_starts(
    gamma: Tensor, h: Tensor, settings: CellSettings, model: ForwardModel, top: float
) -> tuple[Tensor, Tensor]:
    """One (N,) design's copies with other numbers of asperities in contact at zero load:
    (gamma, h) (C, N), the design first. ``top``: the target's largest pressure."""
    hh, order = torch.sort(anchor(h[None]), dim=-1)
    g = gamma[None].gather(-1, order)
    p0 = torch.full((1, 1), ZERO_LOAD * top, dtype=DTYPE)
    with torch.no_grad():
        delta0 = solve_delta(g, hh, settings, p0, sweep_fn=model.sweep, load_fn=model.newton_load)
    d0 = float(delta0[0][0, 0])
    count = int((hh[0] < d0).sum().clamp_min(1))
    n = hh.shape[1]
    heights = [hh[0]]
    for other in range(max(1, count - COUNT_STEPS), min(n, count + COUNT_STEPS) + 1):
        moved = hh[0].clone()
        if other < count:  # lift the last ones in contact above Delta_0
            moved[other:count] = moved[other:count].clamp_min(1.1 * d0)
        elif other > count:  # lower the next ones below it
            moved[count:other] = moved[count:other].clamp_max(0.5 * d0)
        else:
            continue
        heights.append(moved)
    h_c = torch.stack(heights)
    return g.expand(h_c.shape[0], -1), h_c


def offset_polish(
    results: list[DesignResult],
    refine_settings: RefineSettings,
    extra_loss: Callable[[Tensor, Tensor, CellSettings], Tensor] | None,
    model: ForwardModel,
) -> list[DesignResult]:
    """The results, each adhesive design of a target with F_0 > 0 replaced by one nearer
    F_0 where the curve allows it (see the module docstring)."""
    if not model.adhesion:
        return results
    # a design already within F0_TOL of F_0 has nothing to gain here
    missed = {i: _f0_miss(r, model) for i, r in enumerate(results) if has_offset(r)}
    todo = [i for i, miss in missed.items() if miss > F0_TOL]
    if not todo:
        return results
    s = results[0].settings
    gammas, heights, owner = [], [], []
    for j, i in enumerate(todo):
        r = results[i]
        g, h = contact_starts(
            torch.as_tensor(r.gamma, dtype=DTYPE),
            torch.as_tensor(r.h, dtype=DTYPE),
            s,
            model,
            float(r.target.p_star[-1]),
        )
        gammas.append(g)
        heights.append(h)
        owner += [j] * g.shape[0]
    grid = TargetGrid.from_curves(
        [(results[i].target.p_star, results[i].target.alpha) for i in todo],
        refine_settings.grid_points,
    )
    weight = torch.ones_like(grid.p)
    weight[:, 0] = OFFSET_WEIGHT
    rows = replace(grid, weight=weight).rows(torch.tensor(owner))
    raw = FULL.from_design(torch.cat(gammas), torch.cat(heights), s)
    raw = polish(raw, s, rows, refine_settings, FULL, extra_loss, model)
    g1, h1 = FULL.to_design(raw.detach(), s)
    plain = replace(rows, weight=None)
    with torch.no_grad():
        alpha, p_max = model.alpha_at(g1, h1, s, plain.p, exact=True)
    err = curve_error(alpha, plain.alpha, plain.p, p_max)
    miss = (alpha[:, 0] / plain.alpha[:, 0] - 1).abs()  # F_0's relative error
    out = list(results)
    owner_t = torch.tensor(owner)
    for j, i in enumerate(todo):
        r = results[i]
        mine = (owner_t == j).nonzero(as_tuple=True)[0]
        before = missed[i]
        # the curve may get worse by the slack, or up to CURVE_MEET where F_0 then meets
        bound = max(r.error * (1 + OFFSET_SLACK), r.error + OFFSET_FLOOR)
        within = (err[mine] <= bound) | ((err[mine] <= CURVE_MEET) & (miss[mine] <= F0_MEET))
        # nearest F_0 first, all within F0_TOL counting as met; then the smaller error
        keys = [(max(float(miss[k]), F0_TOL), float(err[k]), int(k)) for k in mine[within]]
        if not keys or min(keys)[:2] >= (max(before, F0_TOL), r.error):
            continue
        row = min(keys)[2]
        e, f0 = float(err[row]), float(miss[row])
        note = (
            f"target {r.target.name}: F_0 (the law's offset) weighed in a last polish: off by "
            f"{100 * before:.3g} % -> {100 * f0:.3g} %, error {100 * r.error:.3g} % -> "
            f"{100 * e:.3g} %"
        )
        out[i] = r.redesigned(g1[row].numpy(), h1[row].numpy(), e, note)
    return out


def _f0_miss(result: DesignResult, model: ForwardModel) -> float:
    """The design's F_0 relative error |alpha(0) / alpha_t(0) - 1|."""
    miss = f0_error(result.target, result.gamma, result.h, result.settings, model)
    return math.inf if miss is None else miss


def f0_error(
    target: Target, gamma: np.ndarray, h: np.ndarray, settings: CellSettings, model: ForwardModel
) -> float | None:
    """|F_0,design / F_0,law - 1| of a design (gamma, h (N,)) of an offset law's target
    (F_0 > 0 given by the law, not extrapolated) under ``model``; None for any other target
    or a model without adhesion (no friction at zero load). F_0: the model at zero load,
    just after the cell snaps in (``ZERO_LOAD``, the target's first point)."""
    t = target
    if not (t.p_star.size and t.p_star[0] == 0 and t.alpha[0] > 0) or extrapolated(t):
        return None
    if not model.adhesion:
        return None
    g = torch.as_tensor(np.asarray(gamma), dtype=DTYPE)[None]
    hh = torch.as_tensor(np.asarray(h), dtype=DTYPE)[None]
    p = torch.as_tensor(np.asarray(t.p_star), dtype=DTYPE)[None]
    with torch.no_grad():
        alpha, _ = model.alpha_at(g, hh, settings, p, exact=True)
    value = abs(float(alpha[0, 0]) / float(t.alpha[0]) - 1)
    return value if math.isfinite(value) else math.inf
