"""Which friction laws a cell can follow: the reachable friction coefficient and load range.

With Bowden-Tabor (paper sec. 2.3) a friction law F_f(F_n) on a nominal area A becomes
alpha = F_f / (tau A) at P* = F_n / (A E*), so its friction coefficient is

    mu = F_f / F_n = (alpha / P*) (tau / E*).

A cell of N power-law asperities (gamma in the bounds, each pressed at most Delta_max)
reaches, at a pressure P*, only contact fractions alpha in [lo(P*), hi(P*)]. One asperity
can carry a force f with any gamma whose force at Delta_max reaches f, and gives an area
between the least and the most of those gammas give; each asperity picks its own gamma
and share of the load (or none, idle), so the cell's least and most area at a total force
are the N-fold min-plus and max-plus convolutions of the one-asperity bounds (computed on a
force grid, cached per cell). The largest pressure any cell reaches, P*_reach, is all N at
Delta_max with the gamma of the largest force.

So at a pressure P* the reachable friction coefficient is [lo, hi] / P* times tau / E*:
changing tau / E* scales the law's mu against it, and a larger area lowers the law's P*
(which moves it along these bounds). These exact bounds (:func:`alpha_bounds`) let each
asperity pick its gamma anew at every load, which no one cell does, so they are wider than
what a cell follows: whether a law is reachable is asked of the envelope of a family of
cells (:func:`metainterface.inverse.envelope.reach_violation`, the one reach test), and
:mod:`metainterface.inverse.verdict` reports it in mu.
Closed forms (Sneddon, :mod:`metainterface.physics.sneddon`): for one asperity pressed by d,
a = (d / (kappa c))^(1/gamma), F = 2 gamma / (gamma + 1) d a, A = pi a^2.
"""

from __future__ import annotations

import functools
import math

import numpy as np
import torch

from metainterface.physics.cell import CellSettings
from metainterface.physics.sneddon import log_kc
from metainterface.units._convolution import FORCE_SAMPLES, GAMMA_SAMPLES, _convolve


def alpha_bounds(
    p_star: np.ndarray, settings: CellSettings | None = None, adhesion: float = 0.0
) -> tuple[np.ndarray, np.ndarray, float]:
    """(lo, hi, P*_reach): the contact fraction any cell of ``settings`` reaches at each
    pressure p_star (M,), and the largest pressure any reaches (lo = inf, hi = -inf beyond
    it, and at P* <= 0). adhesion: w [E* R] (``physical.adhesive_reach``), 0 for none."""
    s = settings or CellSettings()
    if adhesion:
        from metainterface.units.adhesive_reach import adhesive_envelope

        force, lo_n, hi_n = adhesive_envelope(s, float(adhesion))
    else:
        force, lo_n, hi_n = _envelope(s)
    p = np.asarray(p_star, dtype=np.float64)
    f = p * s.nominal_area
    reach = float(force[-1] / s.nominal_area)
    inside = (p > 0) & (p <= reach)
    lo = np.interp(f, force, lo_n) / s.nominal_area
    hi = np.interp(f, force, hi_n) / s.nominal_area
    return np.where(inside, lo, np.inf), np.where(inside, hi, -np.inf), reach


@functools.lru_cache(maxsize=8)
def _envelope(s: CellSettings) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(F, least area, most area) of a whole cell on a uniform force grid [R^2 E* units].

    One asperity can carry a force f with any gamma whose force at Delta_max is >= f; the
    least and most area it can give are min_gamma / max_gamma A_gamma(f) over those. Each
    asperity picks its own gamma and share of the load (an idle one carries 0), so the
    cell's extremes are the N-fold min-plus / max-plus convolutions of those, on a grid of
    ``FORCE_SAMPLES`` forces per asperity (exact at the grid's points).
    """
    g = torch.linspace(s.gamma_min, s.gamma_max, GAMMA_SAMPLES, dtype=torch.float64)
    lkc = log_kc(g, s.radius).numpy()
    g = g.numpy()
    c1 = 2 * g / (g + 1) * np.exp(-lkc / g)  # F = c1 d^(1 + 1/gamma)
    f_max = c1 * s.delta_max ** (1 + 1 / g)
    f = np.linspace(0.0, f_max.max(), FORCE_SAMPLES + 1)
    d = (f[:, None] / c1) ** (g / (g + 1))
    area = math.pi * np.exp(2 * (np.log(np.maximum(d, 1e-300)) - lkc) / g) * (d > 0)
    ok = f[:, None] <= f_max * (1 + 1e-12)
    low = np.where(ok, area, np.inf).min(1)
    high = np.where(ok, area, -np.inf).max(1)
    lo_n, hi_n = low, high
    for _ in range(s.n_asperities - 1):
        lo_n = _convolve(lo_n, low, np.minimum)
        hi_n = _convolve(hi_n, high, np.maximum)
    force = np.arange(lo_n.size) * (f[1] - f[0])
    return force, lo_n, hi_n
