"""Calibrate the interface from a friction test of a made design: tau and w (issue 38).

The design's cell (gammas and heights of its design.json; R and the patch's nominal area A
from its physical block) under the adhesive form of the model it was made with, in load
control (``Independent`` or ``Interacting`` with adhesion w / (E* R)):
F_f = tau alpha(F_n / (A E*); w) A. tau enters linearly, so for each w the best tau is
closed-form; w is found by a scan over log w, a finer one about its best, then a bounded
1-D search. The friction jumps where an asperity snaps in at a load the test holds, so w's
uncertainty comes from the profile of the cost (where it rises by k^2 s^2, k Student's t of
the 95 % range, its wider side taken as k sigma), and tau's from its linear part plus its
drift with w over that range.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from metainterface.calibration.refuse import refuse
from metainterface.calibration.sphere import Calibration, check_scales, friction_rows
from metainterface.errors import MetainterfaceError
from metainterface.physics.models import ForwardModel
from metainterface.physics.registry import get_model

#: The adhesion scanned before the 1-D search, in units of E* R (0 is tried too): the
#: adhesive model's range up to ``ADHESION_LIMIT``, 3 points a decade; then 24 a decade
#: about the best of those.
_SCAN = np.logspace(-9.0, 0.0, 28)
_FINE = 24
#: Samples of the approach in the model's sweep: alpha at a test's loads to ~2e-6 (the
#: interpolation between samples) against 8193 on a held-back adhesive cell.
N_DELTA = 1025


def _minimise(cost: Any, unit: float, top: float) -> float:
    """The w [J/m^2] in [0, top] of least ``cost(w)[1]``: a scan over log w (``_SCAN``
    times ``unit`` = E* R, and 0), a finer one about its best, then a bounded 1-D search
    between the fine neighbours (the cost has jumps: a scan first, not a descent)."""
    from scipy.optimize import minimize_scalar

    coarse = np.concatenate([[0.0], _SCAN * unit])
    costs = np.full(coarse.size, np.inf)
    for i, w in enumerate(coarse):  # stickier than one that misses the loads misses them too
        costs[i] = cost(w)[1]
        if not math.isfinite(costs[i]):
            break
    k = int(np.argmin(costs))
    if k == 0 and costs[1] > costs[0]:
        return 0.0
    k = max(k, 1)
    lo, hi = coarse[max(k - 1, 1)], coarse[min(k + 1, coarse.size - 1)]
    fine = np.geomspace(lo, min(hi, top), _FINE * 2 // 3 + 1)
    f_costs = np.array([cost(w)[1] for w in fine])
    j = int(np.argmin(f_costs))
    a, b = fine[max(j - 1, 0)], fine[min(j + 1, fine.size - 1)]
    best_w, best_c = float(fine[j]), float(f_costs[j])
    if b > a:
        sol = minimize_scalar(
            lambda x: cost(math.exp(x))[1],
            bounds=(math.log(a), math.log(b)),
            method="bounded",
            options={"xatol": 1e-4},
        )
        if sol.fun < best_c:
            best_w = float(math.exp(sol.x))
    return best_w


def _profile_edge(
    cost: Any, work: float, least: float, rise: float, side: int, top: float
) -> float:
    """Where the profile cost first rises by ``rise`` from its least at ``work``, on one
    ``side`` (-1: below, 1: above): stepping out by doubling steps, then bisection. NaN
    where it does not within [0, top] (a bound, not an edge)."""
    if not (rise > 0 and math.isfinite(least)):
        return math.nan
    step = max(1e-3 * work, 1e-6 * top)
    inner = work
    for _ in range(40):
        outer = work + side * step
        if outer <= 0 or outer >= top:
            return math.nan
        if cost(outer)[1] - least >= rise:
            break
        inner, step = outer, step * 2.0
    else:
        return math.nan
    for _ in range(10):  # to a thousandth of the last step
        mid = 0.5 * (inner + outer)
        if cost(mid)[1] - least >= rise:
            outer = mid
        else:
            inner = mid
    return 0.5 * (inner + outer)


def adhesive_model(model: str | ForwardModel, adhesion: float) -> ForwardModel:
    """The forward model ``model`` (a name or a ForwardModel) with adhesion w / (E* R)."""
    return get_model(model).with_adhesion(adhesion)


def design_friction(
    normal_force: np.ndarray,
    tau: float,
    work: float,
    design: Any,
    *,
    e_star: float,
    area: float,
    radius: float,
    model: str | ForwardModel = "independent",
) -> np.ndarray:
    """F_f = tau alpha(P*) A [N] of a made design's patch at loads F_n (K,) >= 0 [N].

    design: a Design (its gammas and heights in units of R); e_star E* [Pa]; area: the
    patch's nominal area A [m^2]; radius R [m]; work w [J/m^2]. alpha is the adhesive
    ``model``'s loading curve under a rising force (``independent`` or ``interacting``,
    with adhesion w / (E* R)) at P* = F_n / (A E*); at zero load, the state just after the
    cell snaps in.
    """
    import torch

    fn = np.asarray(normal_force, dtype=np.float64)
    p = fn / (area * e_star)
    q = np.maximum(p, 1e-12 * max(float(p.max()), 1e-300))  # zero load: after the snap-in
    model = adhesive_model(model, work / (e_star * radius))
    g, h = design.tensors(torch.float64)
    with torch.no_grad():
        loads = torch.as_tensor(q)[None]
        alpha = model.alpha_at_loads(g, h, design.settings, loads, n_delta=N_DELTA)[0]
    return tau * alpha.numpy() * area


def calibrate_design(
    normal_force: np.ndarray,
    friction_force: np.ndarray,
    design: Any,
    *,
    e_star: float,
    area: float,
    radius: float,
    source: str = "friction test",
    model: str | ForwardModel = "independent",
    unit: tuple[str, float] = ("N", 1.0),
) -> Calibration:
    """Fit tau and w to a friction test (K,) [N] of a made design's patch.

    design: the Design made; e_star E* [Pa]; area: the patch's nominal area [m^2]; radius:
    the asperity radius R [m]; model: the forward model the design was made with
    (``independent`` or ``interacting``; design.json's "model"). Loads must be >= 0 (the
    loading branch: a pull depends on the path the patch came by); rows with friction <= 0
    are left out; at least 3 rows. A test the model cannot explain is refused
    (``calibration.refuse``); unit: (label, N per unit) of the file's forces, for messages.
    """
    from metainterface.physics.jkr import ADHESION_LIMIT

    check_scales((("modulus E*", e_star), ("area", area), ("radius", radius)))
    fn, ff = friction_rows(normal_force, friction_force, source, loading=True, unit=unit)
    unit = e_star * radius  # w [J/m^2] = w [E* R] * unit

    adhesive_model(model, 0.0)  # a model that takes no adhesion: one line, before the fit

    def shape(w: float) -> np.ndarray:  # friction per unit tau, over the measured friction
        f = design_friction(
            fn, 1.0, w, design, e_star=e_star, area=area, radius=radius, model=model
        )
        return f / ff

    def best(w: float) -> tuple[float, float]:  # (tau, sum of squares) at w
        try:
            m = shape(w)
        except MetainterfaceError:  # so sticky the patch does not reach the test's loads
            return math.nan, math.inf
        tau = float(m.sum() / (m * m).sum())
        return tau, float(((tau * m - 1.0) ** 2).sum())

    work = _minimise(best, unit, ADHESION_LIMIT * unit)
    tau, cost = best(work)
    dof = max(fn.size - 2, 1)
    s2 = cost / dof
    # w's uncertainty from the profile of the cost (tau refitted at each w): the range where
    # it rises by less than k^2 s^2 (k: Student's t of the 95 % range), its wider side taken
    # as k sigma. The friction of a made design is not smooth in w (an asperity that snaps
    # in at a load the test holds moves that row's friction by a jump), so a derivative at
    # the best w can say little; the profile sees the jumps
    from scipy.stats import t as student

    k = float(student.ppf(0.975, dof))
    top = ADHESION_LIMIT * unit
    edges = [_profile_edge(best, work, cost, k * k * s2, side, top) for side in (-1, 1)]
    widths = [abs(e - work) for e in edges if math.isfinite(e)]
    work_sigma = max(widths) / k if widths else math.inf
    # tau's: at fixed w, linear (s^2 / sum m^2); and as the best tau moves with w over w's
    # range (the marginal variance of a linear model: var_cond + slope^2 var_w)
    m = shape(work)
    lo, hi = max(work - work_sigma, 0.0), min(work + work_sigma, top)
    slope = (best(hi)[0] - best(lo)[0]) / (hi - lo) if math.isfinite(work_sigma) else math.nan
    tau_sigma = math.sqrt(s2 / float((m * m).sum()) + (slope * work_sigma) ** 2)
    cov = np.array(
        [
            [tau_sigma**2, slope * work_sigma**2],
            [slope * work_sigma**2, work_sigma**2],
        ]
    )
    extras = getattr(design, "extras", {}) or {}
    target = extras.get("target") if isinstance(extras.get("target"), dict) else {}
    name = extras.get("name") or target.get("name") or "the design"
    cal = Calibration(
        tau=tau,
        work=work,
        tau_sigma=tau_sigma,
        work_sigma=work_sigma,
        covariance=cov,
        rows=int(fn.size),
        residual_rms=float(math.sqrt(cost / fn.size)),
        radius=float(radius),
        e_star=float(e_star),
        contact=f"the cell of {name}, JKR asperities ({adhesive_model(model, 0.0).label})",
        area=float(area),
    )
    refuse(cal, fn, ff, source, unit)
    return cal
