"""The sphere calibration's fit and its 95 % ranges from the profile likelihood (issue 52).

Friction is linear in tau: F_f / F_f,measured = tau m_i(w). The residuals are logarithmic,
ln(tau m_i) (a friction test's scatter is proportional to the force; the relative residual
tau m_i - 1 biases tau by about -2 sigma^2, -0.5 % at 5 % scatter, half a standard error of a
30-row test; the log's bias is -sigma^2 / 2). For each w the best tau is closed-form,
ln tau = -mean(ln m_i), and the least-squares cost C(w) = sum ln(tau m_i)^2 (+ rows that
depend on w alone, a measured pull-off force's ln(F_off,model / F_off)) is a function of
w. w is found by a scan over log w and a bounded 1-D search. The 95 % range of each
parameter is where its profile cost (the other refitted) rises by k^2 s^2 above the
least, s^2 = C_min / (n - 2), k Student's t (n - 2 degrees of freedom): the
likelihood-ratio range of a Gaussian fit, which holds where the model bends in w (at a
row at pull-off friction's derivative in w is infinite, where a linearised covariance
reads w's error as nothing).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class ProfileFit:
    """tau [Pa], w [J/m^2], their standard errors (half the wider side of the 95 % range
    over k), a (2, 2) covariance (the linearised correlation scaled to them), rms relative
    residual, the 95 % ranges {'tau': (lo, hi), 'work': (lo, hi)} (w's lower edge below the
    floor where the profile does not rise by k^2 s^2 above it), and tau_at(w)."""

    tau: float
    work: float
    tau_sigma: float
    work_sigma: float
    covariance: np.ndarray
    rms: float
    ranges: dict[str, tuple[float, float]]
    tau_at: Callable[[float], float]


def fit_profile(
    shape: Callable[[float], np.ndarray],
    extra: Callable[[float], np.ndarray],
    *,
    floor: float,
    scale: float,
    extra_rows: int = 0,
) -> ProfileFit:
    """Fit F_f = tau m(w) F_f,measured: ``shape(w)`` (K,) the model friction per unit tau
    over the measured, ``extra(w)`` ratios model / measured depending on w alone (a
    pull-off force), w >=
    ``floor``; ``scale`` [J/m^2] the test's force scale over pi R (w's scan runs 1e-8 to 1e3
    of it)."""
    from scipy.optimize import minimize_scalar
    from scipy.stats import t as student

    def logs(w: float) -> np.ndarray:
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.log(shape(w))

    def tau_at(w: float) -> float:
        m = logs(w)
        return float(math.exp(-m.mean())) if np.all(np.isfinite(m)) else math.nan

    def cost2(tau: float, w: float) -> float:
        with np.errstate(divide="ignore", invalid="ignore"):
            r = math.log(tau) + logs(w) if tau > 0 else np.array([math.inf])
            c = float((r * r).sum()) + float((np.log(extra(w)) ** 2).sum())
        return c if math.isfinite(c) else math.inf

    def cost(w: float) -> float:
        t = tau_at(w)
        return cost2(t, w) if math.isfinite(t) else math.inf

    grid = np.concatenate([[floor], floor + np.geomspace(1e-8, 1e3, 89) * scale])
    costs = np.array([cost(float(w)) for w in grid])
    j = int(np.argmin(costs))
    work, least = float(grid[j]), float(costs[j])
    a, b = grid[max(j - 1, 0)], grid[min(j + 1, grid.size - 1)]
    if b > a:
        sol = minimize_scalar(cost, bounds=(a, b), method="bounded", options={"xatol": 1e-12 * b})
        if sol.fun < least:
            work, least = float(sol.x), float(sol.fun)
    tau = tau_at(work)
    n = shape(work).size + extra_rows
    dof = max(n - 2, 1)
    k = float(student.ppf(0.975, dof))
    rise = k * k * least / dof
    top = floor + 1e6 * scale

    def edge(f: Callable[[float], float], at: float, side: int, lo: float, hi: float) -> float:
        """Where f first exceeds least + rise stepping from ``at`` to one side within
        [lo, hi]; the bound itself where it does not."""
        step = max(1e-4 * abs(at), 1e-9 * (hi - lo), 1e-300)
        inner = at
        while True:
            outer = at + side * step
            if outer <= lo or outer >= hi:
                outer = lo if side < 0 else hi
                if f(outer) - least < rise:
                    return outer
                break
            if f(outer) - least >= rise:
                break
            inner, step = outer, step * 2.0
        for _ in range(60):
            mid = 0.5 * (inner + outer)
            if f(mid) - least >= rise:
                outer = mid
            else:
                inner = mid
            if abs(outer - inner) <= 1e-9 * max(abs(at), 1e-300):
                break
        return 0.5 * (inner + outer)

    w_lo = edge(cost, work, -1, floor, top) if work > floor else floor
    w_hi = edge(cost, work, 1, floor, top)
    if w_lo <= floor and cost(floor) - least < rise:
        w_lo = floor - (w_hi - work)  # the range reaches below the floor

    def tau_profile(t: float) -> float:  # the cost at tau = t, w refitted in w's wide range
        lo, hi = max(floor, work - 4 * (work - w_lo)), work + 4 * (w_hi - work) + 1e-12 * scale
        ws = np.linspace(lo, hi, 41)
        cs = np.array([cost2(t, float(w)) for w in ws])
        i = int(np.argmin(cs))
        a, b = ws[max(i - 1, 0)], ws[min(i + 1, ws.size - 1)]
        best = float(cs[i])
        if b > a:
            sol = minimize_scalar(lambda w: cost2(t, w), bounds=(a, b), method="bounded")
            best = min(best, float(sol.fun))
        return best

    t_lo = edge(tau_profile, tau, -1, 0.0, 1e6 * tau)
    t_hi = edge(tau_profile, tau, 1, 0.0, 1e6 * tau)
    tau_sigma = max(tau - t_lo, t_hi - tau) / k
    work_sigma = max(work - w_lo, w_hi - work) / k
    # the correlation of the linearised fit, scaled to the profile's standard errors
    h = max(1e-6 * work, 1e-9 * scale)
    with np.errstate(divide="ignore", invalid="ignore"):
        r0 = np.concatenate([logs(work), np.log(extra(work))])
        r1 = np.concatenate([logs(work + h), np.log(extra(work + h))])
    d_tau = np.concatenate([np.ones(n - extra_rows), np.zeros(extra_rows)]) / tau
    jac = np.stack([d_tau, (r1 - r0) / h], 1)
    try:
        lin = np.linalg.inv(jac.T @ jac)
        corr = float(lin[0, 1] / math.sqrt(lin[0, 0] * lin[1, 1]))
    except (np.linalg.LinAlgError, ValueError, ZeroDivisionError):
        corr = 0.0
    if not math.isfinite(corr):
        corr = 0.0
    cov_tw = corr * (tau_sigma / tau) * work_sigma * tau  # in Pa J/m^2 after the scaling
    cov = np.array([[tau_sigma**2, cov_tw], [cov_tw, work_sigma**2]])
    return ProfileFit(
        tau=tau,
        work=work,
        tau_sigma=tau_sigma,
        work_sigma=work_sigma,
        covariance=cov,
        rms=math.sqrt(least / n),
        ranges={"tau": (t_lo, t_hi), "work": (w_lo, w_hi)},
        tau_at=tau_at,
    )
