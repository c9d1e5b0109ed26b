"""The scale search's candidates: which values of the free scale variable to design, their
quick designs and how each is scored, and the second round between the best."""

from __future__ import annotations

from typing import Any

import numpy as np

from metainterface.scaling import search as _scale


def _candidates(fs: _scale.FeasibleScale, var: str, count: int) -> np.ndarray:
    """Values of ``var`` to design: spread (in log) over its feasible ranges, else around
    the least-violating value."""
    spans = fs.ranges[var]
    lo_b, hi_b = fs.bounds[var]
    if spans and _coarse(fs, var):  # the grid points tested, spread over the widest range
        lo, hi = max(spans, key=lambda s: s[1] / s[0])
        grid = _scale.scan_grid((lo_b, hi_b), True)
        inside = grid[(grid >= lo * (1 - 1e-9)) & (grid <= hi * (1 + 1e-9))]
        pick = np.unique(np.round(np.linspace(0, inside.size - 1, min(count, inside.size))))
        return inside[pick.astype(int)]
    if spans:
        lo, hi = spans[0][0], spans[-1][1]
        if len(spans) > 1:  # several ranges: the widest one
            lo, hi = max(spans, key=lambda s: s[1] / s[0])
        # keep off the envelope's edges, where the pointwise estimate is least sure
        inner = (hi / lo) ** 0.1
        return np.geomspace(lo * inner, hi / inner, count) if hi / lo > 1.01 else np.array([lo])
    b = fs.best[var]
    return np.clip(np.geomspace(b / 1.3, b * 1.3, count), lo_b, hi_b)


def _coarse(fs: _scale.FeasibleScale, var: str) -> bool:
    """Whether ``var`` was searched on the coarse grid (the modulus with adhesion): its
    candidates are then the grid points tested, not values between them."""
    return bool(fs.work_of_adhesion) and var == "modulus"


def uncovered(result: Any) -> float:
    """The share of a target's pressure range its design does not reach by Delta_max.

    The relative curve error holds a design's alpha at its last value past its reach, so a
    design that stops short of the law can score well; the scale search adds this share to
    the error, so that it prefers a scale whose design carries the whole law."""
    import torch

    g, h = result.design.tensors()
    with torch.no_grad():
        zero = torch.zeros(1, 1, dtype=g.dtype)
        _, p_max = result.model.alpha_at(g, h, result.design.settings, zero)
    top = float(result.target.p_star_max)
    return max(0.0, 1.0 - float(p_max[0]) / top) if top > 0 else 0.0


def score(result: Any) -> float:
    """A candidate scale's score: its design's curve error, plus the share of the law's
    pressure range it does not reach (``uncovered``), plus, for an offset law, its F_0's
    relative error (``inverse.offset.f0_error``: part of what a design meets; without it a
    scale whose design idles the asperities that give F_0 scored 0.23 % and missed F_0 by
    15 %)."""
    from metainterface.inverse.offset import f0_error

    d = result.design
    miss = f0_error(result.target, d.gamma, d.h, d.settings, result.model)
    return result.error + uncovered(result) + (0.0 if miss is None else miss)


def _closer(values: np.ndarray, errors: np.ndarray) -> np.ndarray:
    """Second-round candidates: the geometric midpoints between the best value and its
    neighbours, and the vertex of the parabola through the three in (log value, log error)
    where it falls between them (a step of golden-section-like refinement, on a batch)."""
    k = int(np.argmin(errors))
    lo, hi = max(k - 1, 0), min(k + 1, values.size - 1)
    x = np.log(values)
    out = [float(np.exp(0.5 * (x[lo] + x[k]))), float(np.exp(0.5 * (x[k] + x[hi])))]
    if 0 < k < values.size - 1:
        y = np.log(np.maximum(errors[lo : hi + 1], 1e-12))
        c = np.polyfit(x[lo : hi + 1], y, 2)
        if c[0] > 0:
            v = -c[1] / (2 * c[0])
            if x[lo] < v < x[hi]:
                out.append(float(np.exp(v)))
    out = np.unique([v for v in out if not np.isclose(v, values, rtol=1e-3).any()])
    return np.asarray(out, dtype=np.float64)


__all__ = ["_candidates", "_closer", "_coarse", "score", "uncovered"]


def _quick_scores(
    at: Any,
    fs: _scale.FeasibleScale,
    values: np.ndarray,
    stem: str,
    effort: Any,
    options: dict[str, Any],
) -> np.ndarray:
    """(V,) each candidate value's score (``score``) from its quick design with ``effort``,
    no BEM check (candidates are ranked on the model; the chosen one is checked); ``at``
    makes the law's target at a value (``choose._AtScale``)."""
    from metainterface.designer.run import design

    targets = [at.target(v, f"{stem}-{i}") for i, v in enumerate(values)]
    # one batch shares one model: candidate moduli with adhesion differ in w / (E* R)
    batches = [[t] for t in targets] if _coarse(fs, at.var) else [targets]
    made = [
        r
        for batch in batches
        for r in design(batch, settings=at.settings, effort=effort, verify=False, **options)
    ]
    return np.array([score(r) for r in made])


def _ranked(
    fs: _scale.FeasibleScale,
    var: str,
    values: np.ndarray,
    quick: Any,
) -> tuple[np.ndarray, np.ndarray]:
    """The candidate values and their quick scores, with a second round between the best
    and its neighbours (not on a coarse grid: its points are the values tested), sorted."""
    errors = quick(values)
    if values.size >= 3 and not _coarse(fs, var):
        more = _closer(values, errors)
        if more.size:
            values = np.concatenate([values, more])
            errors = np.concatenate([errors, quick(more)])
            order = np.argsort(values)
            values, errors = values[order], errors[order]
    return values, errors
