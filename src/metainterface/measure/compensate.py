"""The next print corrected: the systematic map from designed to made, fitted from one or
more (design, registration) pairs, and the geometry to send to the printer so that the
*made* part meets the target.

The map (``PrintMap``): gamma_made = gamma + shift + bias_gamma_k, and
h_made = scale h + bias_h_k (h anchored, min 0; the made heights aligned on the design's
mean, ``register``), the per-asperity biases the mean residuals at lattice index k (kept
only when every pair has N asperities, all seen; else none, the height bias a common
offset). The printed geometry starts from the map's
inverse applied to the design (the made part would then be the design), clipped to the
printer's bounds (the design's gamma bounds, h >= 0), and is refined with the map inside:
the forward model's curve of map(printed) is fitted to the target.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
import torch

from metainterface.errors import MetainterfaceError
from metainterface.measure.predict import ERROR_POINTS, curve_errors, target_of
from metainterface.measure.register import Registration
from metainterface.physics.cell import Design
from metainterface.physics.registry import get_model

#: Steps of the refinement with the map inside.
REFINE_STEPS = 150


@dataclass(frozen=True)
class PrintMap:
    """Designed -> made: gamma shift, height scale, per-asperity biases (N,) [h in R]."""

    gamma_shift: float
    h_scale: float
    gamma_bias: np.ndarray
    h_bias: np.ndarray

    def made(self, gamma: np.ndarray, h: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(gamma, h) as made from printed (gamma, h) (..., N) [h in R, anchored]."""
        h0 = h - np.min(h, axis=-1, keepdims=True)
        return gamma + self.gamma_shift + self.gamma_bias, self.h_scale * h0 + self.h_bias

    def to_dict(self, radius_m: float) -> dict[str, Any]:
        um = 1e6 * radius_m
        return {
            "gamma_shift": self.gamma_shift,
            "h_scale": self.h_scale,
            "gamma_bias": [float(v) for v in self.gamma_bias],
            "h_bias_um": [float(v * um) for v in self.h_bias],
        }


def fit_map(pairs: list[tuple[Design, Registration]]) -> PrintMap:
    """The systematic map from (design, registration) pairs (module docstring)."""
    if not pairs:
        raise MetainterfaceError("compensate needs at least one (design, scan) pair")
    n = pairs[0][0].n_asperities
    dg, hd, hm = [], [], []
    for design, reg in pairs:
        seen = reg.seen > 0
        dg.append(np.where(seen, reg.gamma - design.gamma, np.nan))
        hd.append(np.where(seen, design.h - design.h.min(), np.nan))
        hm.append(np.where(seen, reg.h, np.nan))
    dg_a, hd_a, hm_a = (np.array(v) for v in (dg, hd, hm))
    ok = np.isfinite(dg_a)
    shift = float(dg_a[ok].mean())
    x, y = hd_a[ok], hm_a[ok]
    if np.ptp(x) > 0:
        scale, offset = np.polyfit(x, y, 1)
    else:
        scale, offset = 1.0, float(np.mean(y - x))
    same = all(d.n_asperities == n for d, _ in pairs) and ok.all()
    if same:
        gamma_bias = np.nanmean(dg_a, axis=0) - shift
        h_bias = np.nanmean(hm_a - (scale * hd_a + offset), axis=0) + offset
    else:
        gamma_bias, h_bias = np.zeros(n), np.full(n, offset)
    return PrintMap(float(shift), float(scale), gamma_bias, h_bias)


@dataclass(frozen=True)
class Compensation:
    """printed: the design to send to the printer; pmap: the map used; error_before,
    error_after: predicted made errors (forward model) of the design and of ``printed``,
    each printed as the map says."""

    printed: Design
    pmap: PrintMap
    error_before: float
    error_after: float


def compensate(
    design: Design, pmap: PrintMap, *, model: Any = None, steps: int = REFINE_STEPS
) -> Compensation:
    """Pre-distort ``design`` for the map ``pmap`` (module docstring)."""
    s = design.settings
    target = target_of(design, model)
    h_design = design.h - design.h.min()
    # the inverse: printed such that made = design
    g0 = np.clip(design.gamma - pmap.gamma_shift - pmap.gamma_bias, s.gamma_min, s.gamma_max)
    h0 = (h_design - pmap.h_bias) / pmap.h_scale
    h0 = h0 - h0.min()
    before = _made_error(design.gamma, h_design, pmap, design, target, model)
    start = _made_error(g0, h0, pmap, design, target, model)
    g1, h1 = _refine(g0, h0, pmap, design, target, model, steps)
    after = _made_error(g1, h1, pmap, design, target, model)
    if start <= after:
        g1, h1, after = g0, h0, start
    printed = Design(
        gamma=np.clip(g1, s.gamma_min, s.gamma_max),
        h=h1 - h1.min(),
        settings=s,
        extras={
            **{k: v for k, v in design.extras.items() if k != "provenance"},
            "target": {
                "p_star": [float(v) for v in target[0]],
                "alpha": [float(v) for v in target[1]],
            },
            "compensation": {
                "predicted_made_error_before": before,
                "predicted_made_error_after": after,
                "gamma_shift": pmap.gamma_shift,
                "h_scale": pmap.h_scale,
            },
        },
    )
    return Compensation(printed=printed, pmap=pmap, error_before=before, error_after=after)


def _made_error(g, h, pmap, design, target, model) -> float:
    gm, hm = pmap.made(np.asarray(g), np.asarray(h))
    err, _ = curve_errors(gm[None], hm[None], design, target, model)
    return float(err[0])


def _refine(g0, h0, pmap, design, target, model, steps):
    """Adam on the printed geometry, the map inside, projected onto the bounds."""
    s = design.settings
    p_t, a_t = target
    grid = torch.linspace(0.0, float(p_t[-1]), ERROR_POINTS, dtype=torch.float64)[None]
    ref = torch.as_tensor(np.interp(grid[0].numpy(), p_t, a_t, left=0.0))[None]
    g = torch.tensor(g0, requires_grad=True)
    h = torch.tensor(h0 / s.delta_max, requires_grad=True)
    gb = torch.as_tensor(pmap.gamma_bias)
    hb = torch.as_tensor(pmap.h_bias)
    fm = get_model(model)
    opt = torch.optim.Adam([g, h], lr=0.01)
    best = (float("inf"), g0, h0)
    for _ in range(steps):
        opt.zero_grad()
        hp = h * s.delta_max
        gm = g + pmap.gamma_shift + gb
        hm = pmap.h_scale * (hp - hp.min()) + hb
        alpha, p_max = fm.alpha_at(gm[None], hm[None], s, grid, exact=True)
        reached = grid <= p_max[:, None]
        loss = ((torch.where(reached, alpha - ref, 0.0) ** 2).sum() / (ref**2).sum()).sqrt()
        loss = loss + torch.relu(1.0 - p_max / grid[0, -1]).sum()
        value = float(loss.detach())
        if value < best[0]:
            best = (value, g.detach().numpy().copy(), hp.detach().numpy().copy())
        loss.backward()
        opt.step()
        with torch.no_grad():
            g.clamp_(s.gamma_min, s.gamma_max)
            h.clamp_(min=0.0)
    return best[1], best[2]
