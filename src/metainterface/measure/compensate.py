"""The next print corrected, checked as it will be made.

The process (:class:`Process`), modelled from the scan(s): the systematic map from designed
to made (``PrintMap``: gamma_made = gamma + shift + bias_gamma_k, h_made = scale h +
bias_h_k, h anchored at min 0, the made heights aligned on the design's mean as
``register`` aligns them; the per-asperity biases the mean residuals at lattice index k,
kept only when every pair has N asperities, all seen), and what the power-law family cannot
express: tips cut flat ``flat_depth`` below their apex, and the printer's layer levels
(``measure.shapes.Terraces``: read from the scan, or the step given as ``z_step``). The
made cell of any printed geometry follows: the map's power laws, cut, on the levels.

The printed geometry starts from the map's inverse applied to the design (clipped to the
printer's bounds: the design's gamma bounds, h >= 0) refined in the forward model with the
map inside; then, since the cuts and the layers move the curve in ways the family cannot,
the made cell of that print is solved in BEM and the ratio of its curve to the family's
corrects the target the family is refined to, a few rounds. Every candidate is judged by
the BEM of its predicted made cell at loads over the target's range; the best is kept only
if it beats the design itself printed as it is.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np
import torch

from metainterface._threads import uses_threads
from metainterface.errors import MetainterfaceError
from metainterface.measure.predict import (
    bem_error,
    coarse_grid,
    loads_over,
    model_alpha,
    solve_cell,
    target_of,
)
from metainterface.measure.register import Registration
from metainterface.measure.shapes import Shapes, Terraces, on_levels
from metainterface.measure.surface import asperity_index, lattice_surface
from metainterface.physics.cell import Design
from metainterface.physics.grid_error import error_grid, grid_curve_error
from metainterface.physics.registry import get_model

#: Steps of the refinement with the map inside.
REFINE_STEPS = 150
#: Rounds of the BEM correction after the family's own.
ROUNDS = 3
#: Fewest grid points per asperity pitch the candidates are judged on: on coarser grids the
#: BEM/family ratio carries the grid's own error into the correction (at 32 a pitch the
#: correction of a plain print stopped at 1 % where 64 reached 0.3 %).
LOOP_POINTS = 64
#: Each round refines towards the target over the BEM/family ratio to these powers (the
#: full correction, and half of it where the full one overshoots).
DAMPING = (1.0, 0.5)


def solves(rounds: int = ROUNDS) -> int:
    """The BEM solves ``compensate`` makes (for a progress bar)."""
    return 1 + 2 + rounds * len(DAMPING) + 2


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
class Process:
    """How the printer makes a geometry: ``pmap`` (designed -> made power laws),
    ``flat_depth`` [R] (tips cut this far below their apex; 0: none) and ``terraces`` (the
    layer levels in the made heights' frame, or None)."""

    pmap: PrintMap
    flat_depth: float = 0.0
    terraces: Terraces | None = None

    def made_cell(self, gamma: np.ndarray, h: np.ndarray, design: Design, grid: int):
        """(grid, grid) heights [R] of the made cell of the printed (gamma, h) (N,)."""
        s = design.settings
        gm, hm = self.pmap.made(np.asarray(gamma, float), np.asarray(h, float))
        spacing = s.cell_side / grid
        u, v = np.meshgrid(np.arange(grid) * spacing, np.arange(grid) * spacing)
        z = lattice_surface(u, v, -hm, gm, s)
        if self.flat_depth > 0:
            k = asperity_index(u, v, s)
            z = np.minimum(z, -hm[k] - self.flat_depth)
        if self.terraces is not None:
            z = on_levels(z, self.terraces)
        return z

    def to_dict(self, radius_m: float) -> dict[str, Any]:
        um = 1e6 * radius_m
        t = self.terraces
        return {
            "map": self.pmap.to_dict(radius_m),
            "flat_depth_um": self.flat_depth * um,
            "layer_step_um": None if t is None else t.step * um,
            "layer_phase_um": None if t is None else t.phase * um,
            "layer_step_given": None if t is None else t.given,
        }


def process_from(
    pairs: list[tuple[Design, Registration, Shapes]], z_step: float | None = None
) -> Process:
    """The process from (design, registration, shapes) triples: the map (``fit_map``), the
    flat depth (``_flat_depth``, from the flat tips seen: the fitted apex and the plateau)
    and the layer levels of the first scan that shows them (step ``z_step`` [R] if given)."""
    pmap = fit_map([(d, r) for d, r, _ in pairs])
    terraces = next((sh.terraces for _, _, sh in pairs if sh.terraces is not None), None)
    apex, plateau = [], []
    for _, reg, shapes in pairs:
        flat = (shapes.flat_radius > 0) & (reg.seen > 0)
        apex.extend((-reg.h[flat]).tolist())
        plateau.extend(shapes.plateau[flat].tolist())
    depth = _flat_depth(np.array(apex), np.array(plateau), terraces)
    if z_step is not None and terraces is not None and not terraces.given:
        terraces = Terraces(z_step, terraces.phase, terraces.coherence, given=True)
    elif z_step is not None and terraces is None:
        terraces = Terraces(z_step, 0.0, 0.0, given=True)
    return Process(pmap=pmap, flat_depth=depth, terraces=terraces)


def _flat_depth(apex: np.ndarray, plateau: np.ndarray, terraces: Terraces | None) -> float:
    """The depth [R] the tips are cut below their apex (N,) to their plateaus (N,). On
    layers a plateau is the level nearest apex - depth, so each says depth only to within
    a step; the depths that put every plateau on its level are an interval, whose middle is
    kept. Without layers, the median of apex - plateau."""
    if apex.size == 0:
        return 0.0
    cut = apex - plateau
    if terraces is None:
        return max(0.0, float(np.median(cut)))
    trial = np.linspace(0.0, float(cut.max()) + terraces.step, 801)
    miss = np.abs(on_levels(apex[None] - trial[:, None], terraces) - plateau[None]).sum(1)
    best = trial[miss <= miss.min() + 1e-3 * terraces.step]
    return float(np.median(best))


@dataclass(frozen=True)
class Compensation:
    """The correction. printed: the design to send to the printer, or None where no
    candidate beats printing the design as it is; process: the model it was made for;
    error_before, error_after: the made errors (BEM of the predicted made cell, at p_star)
    of the design and of ``printed`` (the design's again where printed is None);
    alpha_before, alpha_after: (K,) their BEM curves; p_star: (K,) the loads;
    error_family: the forward model's error of ``printed`` made by the map alone (what the
    family predicts); limits: what the correction cannot reach, in words."""

    printed: Design | None
    process: Process
    error_before: float
    error_after: float
    error_family: float
    p_star: np.ndarray
    alpha_before: np.ndarray
    alpha_after: np.ndarray
    limits: list[str]

    @property
    def pmap(self) -> PrintMap:
        return self.process.pmap

    @property
    def improved(self) -> bool:
        return self.printed is not None


@uses_threads()
def compensate(
    design: Design,
    process: Process | PrintMap,
    *,
    model: Any = None,
    steps: int = REFINE_STEPS,
    grid: int = 192,
    loads: int = 8,
    rounds: int = ROUNDS,
    engine: Any = None,
    device: Any = "auto",
    radius_m: float | None = None,
    report: Callable[[int], Any] | None = None,
) -> Compensation:
    """Pre-distort ``design`` for ``process`` (module docstring), each candidate judged by
    the BEM of its predicted made cell on grid x grid at ``loads`` loads over the target's
    range (the candidates on a grid half as fine, where it keeps ``LOOP_POINTS`` a pitch; the
    best of them, the family's own correction and the design itself on the full grid).
    radius_m: R [m], recorded in the printed design file (so that ``export`` need not be
    told it again). report: called with 1 after each BEM solve
    (``solves(rounds)`` of them)."""
    if isinstance(process, PrintMap):
        process = Process(pmap=process)
    pmap = process.pmap
    s = design.settings
    target = target_of(design, model)
    p = loads_over(target, loads)
    h_design = design.h - design.h.min()

    # candidates on the coarse grid where it still holds LOOP_POINTS per asperity pitch
    loop_grid = coarse_grid(grid, s.n_side)
    if loop_grid < LOOP_POINTS * s.n_side:
        loop_grid = grid

    # a geometry judged twice on one grid is solved once: where the coarse grid is the full
    # one, the final judgement repeats two of the candidates' (2 of 11 solves)
    seen: dict[tuple[int, bytes, bytes], tuple[float, np.ndarray]] = {}

    def judged(g: np.ndarray, h: np.ndarray, m: int) -> tuple[float, np.ndarray]:
        key = (m, np.asarray(g, float).tobytes(), np.asarray(h, float).tobytes())
        if key not in seen:
            path = solve_cell(
                process.made_cell(g, h, design, m), design, p, engine=engine, device=device
            )
            seen[key] = (float(bem_error(p, path.alpha, target)[0]), path.alpha)
        if report is not None:
            report(1)
        return seen[key]

    before, a_before = judged(design.gamma, h_design, grid)
    # the family's own correction: the map's inverse, as it is and refined with the map inside
    g0 = np.clip(design.gamma - pmap.gamma_shift - pmap.gamma_bias, s.gamma_min, s.gamma_max)
    h0 = (h_design - pmap.h_bias) / pmap.h_scale
    h0 = h0 - h0.min()
    family_own = _refine(g0, h0, pmap, design, target, model, steps)
    candidates = [(g0, h0), family_own]
    best: tuple[float, np.ndarray, np.ndarray, np.ndarray] | None = None
    p_t, a_t = target
    # a round whose best is the last round's refines from the same start towards the same
    # targets: those refinements (150 steps each) are made once
    refinements: dict[tuple[bytes, ...], tuple[np.ndarray, np.ndarray]] = {}

    def refined(g: np.ndarray, h: np.ndarray, a: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        key = tuple(np.asarray(v, float).tobytes() for v in (g, h, a))
        if key not in refinements:
            refinements[key] = _refine(g, h, pmap, design, (p_t, a), model, steps)
        return refinements[key]

    # candidates judged on the coarse grid (a quarter of the cost; its discretisation is
    # common to them all), the best one again on the full grid
    for i in range(rounds + 1):
        for g, h in candidates:
            err, alpha = judged(g, h, loop_grid)
            if best is None or err < best[0]:
                best = (err, g, h, alpha)
        if i == rounds:
            break
        # the BEM over the family at the loads: the part of the curve the family cannot say
        gm, hm = pmap.made(best[1], best[2])
        fam, _ = model_alpha(gm[None], hm[None], design, p, model)
        with np.errstate(divide="ignore", invalid="ignore"):
            ratio = np.where(fam[0] > 0, best[3] / fam[0], 1.0)
        ratio = np.interp(p_t, p, np.clip(np.nan_to_num(ratio, nan=1.0, posinf=1.0), 0.2, 5.0))
        candidates = [refined(best[1], best[2], a_t / ratio**lam) for lam in DAMPING]
    assert best is not None
    # on the full grid: the coarse grid's best, and the family's own correction (where the
    # made cell is nearly the family's, the coarse grid's own error can misrank them)
    final = []
    for g, h in ((best[1], best[2]), family_own):
        err, alpha = judged(g, h, grid)
        final.append((err, g, h, alpha))
    best = min(final, key=lambda c: c[0])
    assert best is not None
    after, g1, h1, a_after = best
    gm, hm = pmap.made(g1, h1)
    family, _ = grid_curve_error(gm[None], hm[None], design.settings, target, model)
    limits = _limits(design, g1, p, a_after, target, after)
    printed = None
    if after >= before:
        limits.insert(
            0,
            f"no correction beats the design printed as it is ({100 * before:.3g} % made "
            f"error; the best correction reads {100 * after:.3g} %): none is written",
        )
        after, a_after = before, a_before
    else:
        extras = {k: v for k, v in design.extras.items() if k not in ("provenance", "physical")}
        extras["target"] = {"p_star": [float(v) for v in p_t], "alpha": [float(v) for v in a_t]}
        if radius_m is not None:
            extras["physical"] = {"radius_m": float(radius_m)}
        extras["compensation"] = {
            "predicted_made_error_before": before,
            "predicted_made_error_after": after,
            "predicted_by": f"BEM of the predicted made cell, {grid}^2, {loads} loads",
            "candidates_judged_on": f"{loop_grid}^2",
            "family_error_after": float(family[0]),
            "process": process.to_dict(radius_m if radius_m is not None else 1.0),
            "process_units": "um" if radius_m is not None else "units of R (no radius given)",
            "limits": limits,
        }
        printed = Design(
            gamma=np.clip(g1, s.gamma_min, s.gamma_max), h=h1 - h1.min(), settings=s, extras=extras
        )
    return Compensation(
        printed=printed,
        process=process,
        error_before=before,
        error_after=after,
        error_family=float(family[0]),
        p_star=p,
        alpha_before=a_before,
        alpha_after=a_after,
        limits=limits,
    )


def _limits(
    design: Design,
    gamma: np.ndarray,
    p: np.ndarray,
    alpha: np.ndarray,
    target: tuple[np.ndarray, np.ndarray],
    error: float,
) -> list[str]:
    """What the correction cannot reach, in words."""
    s = design.settings
    out = []
    low = np.flatnonzero(gamma <= s.gamma_min + 1e-6)
    high = np.flatnonzero(gamma >= s.gamma_max - 1e-6)
    if low.size:
        out.append(
            f"asperities {', '.join(map(str, low))} at the printer's lowest exponent "
            f"({s.gamma_min:g}): they cannot be made blunter"
        )
    if high.size:
        out.append(
            f"asperities {', '.join(map(str, high))} at the highest exponent ({s.gamma_max:g})"
        )
    ref = np.interp(p, target[0], target[1], left=0.0)
    with np.errstate(divide="ignore", invalid="ignore"):
        rel = np.where(ref > 0, alpha / ref - 1.0, 0.0)
    if error > 0.01 and rel.size:
        j = int(np.argmax(np.abs(rel)))
        out.append(
            f"the made curve stays {100 * rel[j]:+.2g} % off the target at P* = {p[j]:.3g} "
            f"(load {j + 1} of {len(p)}): the cut tips and the layers decide it there"
        )
    return out


def _refine(g0, h0, pmap, design, target, model, steps):
    """Adam on the printed geometry, the map inside, projected onto the bounds."""
    s = design.settings
    grid_np, ref_np = error_grid(target)
    grid, ref = torch.as_tensor(grid_np)[None], torch.as_tensor(ref_np)[None]
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
