"""The stages of a reproduction run: each calls the package, saves its figures and returns
the numbers behind them (JSON-ready) for results.md.

Stages share what they compute through ``Context.data`` (the dataset and the surrogate's
test predictions of fig. 3, the designs of fig. 5). The stages that learn (the dataset,
fig. 3 and fig. 4) are ``reproduce.learning``'s; this module holds the closed forms (fig. 1),
the design comparison (fig. 5), the BEM validation (fig. 6) and the run's plan.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import asdict
from typing import Any

import numpy as np
import torch

from metainterface.designer.curve_result import design_curve
from metainterface.errors import MetainterfaceError
from metainterface.inverse import METHODS, builtin_target, design
from metainterface.physics.cell import Design
from metainterface.physics.sneddon import area, force, shape_constant
from metainterface.plots import plot_comparison, plot_validation
from metainterface.reproduce.context import Context, pct
from metainterface.reproduce.figures import plot_asperities
from metainterface.reproduce.learning import clip_gamma, median_row, stage_fig3, stage_fig4
from metainterface.reproduce.scales import PAPER
from metainterface.surrogate.checkpoint import load_model
from metainterface.validation import available_cpus, validate_design

OOD_TARGETS: tuple[str, ...] = ("saturating", "bilinear", "linear")


# -- fig. 1 and table 1 ---------------------------------------------------------------------

FIG1_GAMMAS: tuple[float, ...] = (1.0, 1.5, 2.0, 3.0, 5.0, 10.0, 100.0)

#: Table 1 of the paper: gamma -> (F(A) with E* = 1 for radius R, exponent of dF/dA in A).
TABLE1: dict[float, tuple[Callable[[np.ndarray, float], np.ndarray], float, str]] = {
    1.0: (lambda a, r: a / 4.0, 0.0, "E* A / 4"),
    2.0: (
        lambda a, r: 4.0 / (3.0 * r * math.pi**1.5) * a**1.5,
        0.5,
        "4 E* A^(3/2) / (3 R pi^(3/2))",
    ),
    3.0: (lambda a, r: 9.0 / (16.0 * math.pi * r**2) * a**2, 1.0, "9 E* A^2 / (16 pi R^2)"),
}


def _single(gamma: float, delta: np.ndarray, radius: float) -> tuple[np.ndarray, np.ndarray]:
    g = torch.full((delta.size,), gamma, dtype=torch.float64)
    d = torch.as_tensor(delta, dtype=torch.float64)
    return force(g, d, radius).numpy(), area(g, d, radius).numpy()


def _area_on(force_grid: np.ndarray, gamma: float) -> np.ndarray:
    """A(F) of one asperity (R = E* = 1) on ``force_grid``, NaN beyond its range."""
    f, a = _single(gamma, np.logspace(-12, 0, 3000), 1.0)
    ok = (f > 0) & (a > 0)
    la = np.interp(np.log(force_grid), np.log(f[ok]), np.log(a[ok]), left=np.nan, right=np.nan)
    return np.exp(la)


def stage_fig1(ctx: Context) -> dict[str, Any]:
    """fig. 1a-b from the Sneddon closed forms; table 1 checked against them."""
    r = np.linspace(-1.0, 1.0, 401)
    profiles = {
        g: float(shape_constant(torch.tensor(g, dtype=torch.float64))) * np.abs(r) ** g
        for g in FIG1_GAMMAS
    }
    f_grid = np.logspace(-8, -1, 240)
    areas = {g: _area_on(f_grid, g) for g in FIG1_GAMMAS}
    dense = np.stack([_area_on(f_grid, g) for g in np.geomspace(1.0, 100.0, 60)])
    envelope = (np.nanmin(dense, axis=0), np.nanmax(dense, axis=0))
    slopes = []
    for g in FIG1_GAMMAS:
        ok = np.isfinite(areas[g])
        slope = float(np.polyfit(np.log(f_grid[ok]), np.log(areas[g][ok]), 1)[0])
        slopes.append({"gamma": g, "slope": slope, "paper": 2.0 / (g + 1.0)})
    fig = plot_asperities(r, profiles, f_grid, areas, envelope, areas[1.0], math.pi)
    worst = max(abs(s["slope"] - s["paper"]) for s in slopes)
    ctx.save(
        "fig1_asperities",
        fig,
        "Paper fig. 1a-b (fig:asp_shape_limits). (a) Power-law asperity profiles "
        "f(r) = c |r|^gamma with c = 1/(2 R^(gamma-1)), from the cone (gamma = 1, darkest) to "
        "gamma = 100 (lightest); all reach f = R/2 at r = R. (b) Contact area A against load F "
        "of single asperities (Sneddon closed forms of metainterface.physics.sneddon, R = E* = "
        "1) on log-log axes; grey: the band covered by gamma in [1, 100], between the cone "
        "(A ~ F) and the flat punch (A = pi R^2). Fitted log-log slopes match 2/(gamma+1) "
        f"within {worst:.1e}. Panel (c) of the paper (a schematic) is not reproduced.",
    )

    radius = 2.0  # table 1 carries R explicitly: check it away from R = 1
    delta = np.logspace(-4, -1.5, 60) * radius
    table = []
    for g, (closed_form, exponent, text) in TABLE1.items():
        f, a = _single(g, delta, radius)
        dev = float(np.max(np.abs(f / closed_form(a, radius) - 1.0)))
        dfda = np.gradient(f, a)
        fitted = float(np.polyfit(np.log(a[2:-2]), np.log(dfda[2:-2]), 1)[0])
        table.append(
            {
                "gamma": g,
                "force_law": text,
                "max_rel_dev": dev,
                "stiffness_exponent": fitted,
                "paper_exponent": exponent,
            }
        )
    return {"slopes": slopes, "table1": table, "table1_radius": radius}


# -- fig. 5 ---------------------------------------------------------------------------------


def stage_fig5(ctx: Context) -> dict[str, Any]:
    """The three out-of-distribution targets by the three methods (fig. 5)."""
    sc = ctx.scale
    settings = ctx.data.get("settings") or load_model(ctx.model_path)[1]
    ctx.data["settings"] = settings
    results: dict[str, dict[str, Any]] = {}
    for name in OOD_TARGETS:
        target = builtin_target(name)
        results[name] = {}
        for method in METHODS:
            results[name][method] = design(
                [target],
                method,
                settings=settings,
                model_path=ctx.model_path,
                starts=sc.starts,
                seed=0,
                refine_settings=sc.refine,
                hedge=0,  # the paper's pipeline: the zero-shot prediction is the only start
            )[0]
    ctx.data["designs"] = results
    per_target = [[results[t][m] for m in METHODS] for t in OOD_TARGETS]
    curves = [
        [design_curve(Design(r.gamma, r.h, settings), r.model, steps=512) for r in row]
        for row in per_target
    ]
    fig = plot_comparison(per_target, curves)
    rows = {
        t: {
            m: {
                "zero_shot_error": r.initial_error,
                "error": r.error,
                "seconds": r.seconds,
                "gamma": r.gamma.tolist(),
                "h": (r.h / settings.delta_max).tolist(),
            }
            for m, r in per.items()
        }
        for t, per in results.items()
    }
    summary = "; ".join(
        f"{t}: " + ", ".join(f"{m} {pct(rows[t][m]['error'])}" for m in METHODS)
        for t in OOD_TARGETS
    )
    rs = sc.refine
    ctx.save(
        "fig5_comparison",
        fig,
        "Paper fig. 5 (fig:multistart_hertz_comparison). Out-of-distribution targets "
        "(saturating, bilinear, linear; black) designed by the shipped surrogate followed by "
        "the multi-stage L-BFGS refinement (blue; the paper's pipeline, no hedge starts), by "
        f"{sc.starts}-start direct optimisation "
        f"(green; the paper: 50 starts) and by a {sc.starts}-start Hertz-only baseline (gamma "
        f"= 2, orange); refinement {rs.stages} stages x {rs.steps_per_stage} steps x "
        f"{rs.iterations} iterations. Legend: relative curve error and wall time per target "
        f"on this machine. Errors: {summary}.",
        starts=sc.starts,
    )
    return {"starts": sc.starts, "refine": asdict(rs), "targets": rows}


# -- fig. 6 and appendix D ------------------------------------------------------------------


def _validate(ctx: Context, name: str, design_: Design, target, title: str, text: str) -> dict:
    sc = ctx.scale
    jobs = sc.bem_jobs or max(1, min(available_cpus(), sc.bem_loads))
    res = validate_design(
        design_,
        grid=sc.bem_grid,
        loads=sc.bem_loads,
        jobs=jobs,
        tolerance=sc.bem_tolerance,
        name=name,
    )
    ctx.save(
        name,
        plot_validation(res, target=target, title=title),
        f"{text} {'Tamaas' if res.engine == 'tamaas' else 'torch'} BEM (Polonsky-Keer-Rey, "
        f"tolerance {sc.bem_tolerance:g}) on a "
        f"{res.grid} x {res.grid} grid (the paper: 768) at {len(res.p_star)} loads up to P* at "
        f"Delta_max, against the independent-asperity model. Largest relative error of alpha: "
        f"{pct(res.max_rel_err)} over all loads, {pct(res.max_rel_err_upper)} over the upper "
        f"half (the paper: < 3 %). Largest local pressure p/E* = {res.p_max.max():.3g}.",
        grid=res.grid,
        loads=len(res.p_star),
    )
    s = res.summary()
    s.update(
        gamma_min=float(design_.gamma.min()),
        rel_err=res.rel_err.tolist(),
        p_star=res.p_star.tolist(),
        jobs=jobs,
    )
    return s


def stage_fig6(ctx: Context) -> dict[str, Any]:
    """BEM validation of the surrogate's design of one target (fig. 6) and of zero-shot
    designs of test curves of several categories (appendix D)."""
    sc, settings = ctx.scale, ctx.data["settings"]
    out = {}
    r = ctx.data["designs"][sc.bem_target]["surrogate"]
    name = f"fig6_bem_{sc.bem_target}"
    out[name] = _validate(
        ctx,
        name,
        Design(r.gamma, r.h, settings),
        (r.target.p_star, r.target.alpha),
        f"{sc.bem_target} target: surrogate + refinement design",
        "Paper fig. 6 (fig:bem_validation). The surrogate-guided design of the "
        f"{sc.bem_target} target (fig. 5): (left) alpha(P*) of the target, the model and BEM, "
        "(centre) the cell's topography, (right) p/E* at the largest load.",
    ) | {"source": f"{sc.bem_target} target, surrogate + refinement"}
    pred, test = ctx.data["pred"], ctx.data["test"]
    for cat in sc.bem_categories:
        i = median_row(pred, cat)
        if i is None:
            continue
        p = np.linspace(0.0, 1.0, test.alpha_hat.shape[1]) * test.p_star_max[i]
        name = f"appD_bem_{cat}"
        out[name] = _validate(
            ctx,
            name,
            Design(clip_gamma(pred.gamma[i], settings), pred.h[i], settings),
            (p, test.alpha_hat[i] * test.alpha_max[i]),
            f"{cat} test curve #{i}: zero-shot surrogate design",
            "Paper appendix D (fig:bem_additional). The shipped surrogate's zero-shot design "
            f"for a {cat} test curve (the median-error one, test row {i}; target = the test "
            "curve): (left) alpha(P*) of target, model and BEM, (centre) topography, (right) "
            "p/E* at the largest load.",
        ) | {"source": f"{cat} test row {i}, zero-shot"}
    return {"designs": out, "paper": {k: PAPER[k][0] for k in ("bem_max_rel_err", "model_error")}}


STAGES: dict[str, tuple[Callable[[Context], dict[str, Any]], str, tuple[str, ...]]] = {
    "fig1": (stage_fig1, "single asperities (fig. 1a-b) and table 1", ()),
    "fig3": (stage_fig3, "dataset, test-set reconstructions (fig. 3) and the wall case", ()),
    "fig4": (stage_fig4, "training dynamics (fig. 4a-f)", ("fig3",)),
    "fig5": (stage_fig5, "surrogate vs multistart vs Hertz (fig. 5)", ()),
    "fig6": (stage_fig6, "BEM validation (fig. 6, appendix D)", ("fig3", "fig5")),
}


def plan(only: list[str] | tuple[str, ...] | None) -> list[str]:
    """The stages to run, in order: ``only`` (None: all) and what they need."""
    if not only:
        return list(STAGES)
    unknown = [s for s in only if s not in STAGES]
    if unknown:
        raise MetainterfaceError(f"unknown stage {unknown[0]!r}; stages are {', '.join(STAGES)}")
    wanted = set(only)
    for s in only:
        wanted.update(STAGES[s][2])
    return [s for s in STAGES if s in wanted]
