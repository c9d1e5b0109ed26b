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
what a cell follows. :func:`reachability` therefore asks the one reach test the design
asks too (:func:`~metainterface.inverse.envelope.reach_violation`: the envelope of a
family of cells), and reports mu in its terms.
Closed forms (Sneddon, :mod:`metainterface.physics.sneddon`): for one asperity pressed by d,
a = (d / (kappa c))^(1/gamma), F = 2 gamma / (gamma + 1) d a, A = pi a^2.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

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


@dataclass(frozen=True, repr=False)
class Reachability:
    """Whether a cell can follow a friction law (or an alpha(P*) target), in its terms.

    Attributes
    ----------
    reachable : bool
        Every point of the law lies within the bounds (``TOLERANCE`` allowed) and its
        largest load within the load range.
    law_mu : (float, float)
        The law's friction coefficient F_f / F_n, smallest and largest (loads > 0).
    reachable_mu : (float, float)
        The friction coefficient a cell reaches at the law's loads at this tau / E*:
        smallest and largest over those loads (at its largest load the range is narrowest;
        ``mu_at_largest_load`` gives it).
    mu_at_largest_load : (float, float)
        The reachable mu at the law's largest load within reach.
    load_range : (float, float)
        The normal force a cell reaches on this area [N]: 0 to P*_reach A E*.
    law_load : (float, float)
        The law's normal-force range [N].
    coverage : float
        The fraction of the law's load range within reach.
    units : bool
        False for a target without a friction law: then mu is alpha / P* (mu at tau = E*)
        and loads are P*.
    message : str
        One or two lines: the law's mu, the reachable mu and what would make it reachable.
    """

    reachable: bool
    law_mu: tuple[float, float]
    reachable_mu: tuple[float, float]
    mu_at_largest_load: tuple[float, float]
    load_range: tuple[float, float]
    law_load: tuple[float, float]
    coverage: float
    units: bool
    message: str

    def __bool__(self) -> bool:
        return self.reachable

    def __repr__(self) -> str:
        return f"Reachability(reachable={self.reachable}: {self.message})"


def _fmt(lo: float, hi: float) -> str:
    return f"{lo:.3g}" if math.isclose(lo, hi, rel_tol=1e-3) else f"{lo:.3g}-{hi:.3g}"


def reachability(
    normal_force: np.ndarray,
    friction_force: np.ndarray,
    *,
    shear_strength: float = 1.0,
    e_star: float = 1.0,
    area: float = 1.0,
    settings: CellSettings | None = None,
    units: bool = True,
    adhesion: float = 0.0,
) -> Reachability:
    """Whether a friction law (K,) [N] is reachable at tau [Pa], E* [Pa] and a nominal area
    [m^2] by cells of ``settings``. With ``units=False`` the inputs are P* and alpha (and
    tau = E* = A = 1): the same test on a dimensionless target. adhesion: w / (E* R), for
    cells of JKR asperities (the same test, on the envelope of adhesive cells)."""
    fn = np.asarray(normal_force, dtype=np.float64)
    ff = np.asarray(friction_force, dtype=np.float64)
    keep = fn > 0
    fn, ff = fn[keep], ff[keep]
    p = fn / (area * e_star)
    alpha = ff / (shear_strength * area)
    # the one reach test (feasible_scale and design ask it too); imported here because
    # metainterface.inverse imports this module
    from metainterface.inverse.envelope import reach_violation, reachable_envelope

    cell = settings or CellSettings()
    lo, hi, p_reach = reachable_envelope(p, cell, adhesion=adhesion)
    ok = reach_violation(p, alpha, cell, adhesion=adhesion) == 0
    to_mu = shear_strength / e_star  # mu = (alpha / P*) tau / E*
    law_mu = ff / fn
    within = p <= p_reach
    f_reach = p_reach * area * e_star
    coverage = float(min(1.0, f_reach / fn.max()))
    reachable = bool(ok.all())
    if within.any():
        mu_lo, mu_hi = lo[within] / p[within] * to_mu, hi[within] / p[within] * to_mu
        reach_mu = (float(mu_lo.min()), float(mu_hi.max()))
        top = int(np.flatnonzero(within)[-1])
        at_top = (float(lo[top] / p[top] * to_mu), float(hi[top] / p[top] * to_mu))
    else:
        reach_mu = at_top = (math.nan, math.nan)
    force_unit, mu_name = (" N", "mu") if units else ("", "alpha/P*")
    law = (
        f"the law's {mu_name} is {_fmt(law_mu.min(), law_mu.max())} "
        f"({fn.min():.3g}-{fn.max():.3g}{force_unit})"
    )
    where = f" at E* = {_pa(e_star)}, tau = {_pa(shear_strength)}" if units else ""
    if reachable:
        message = (
            f"reachable: {law}; a cell reaches {mu_name} {_fmt(*at_top)} at its largest load{where}"
        )
    elif within.any():
        message = (
            f"not reachable: {law};{where} a cell reaches {mu_name} {_fmt(*reach_mu)} at these "
            f"loads ({_fmt(*at_top)} at {fn[within][-1]:.3g}{force_unit}) and loads up to "
            f"{f_reach:.3g}{force_unit}.\n"
        )
    else:
        message = (
            f"not reachable: {law};{where} a cell reaches loads up to "
            f"{f_reach:.3g}{force_unit} only.\n"
        )
    if not reachable:
        message += _advice(p, alpha, lo, hi, within, f_reach, fn, shear_strength, units)
    return Reachability(
        reachable=reachable,
        law_mu=(float(law_mu.min()), float(law_mu.max())),
        reachable_mu=reach_mu,
        mu_at_largest_load=at_top,
        load_range=(0.0, float(f_reach)),
        law_load=(float(fn.min()), float(fn.max())),
        coverage=coverage,
        units=units,
        message=message,
    )


def _pa(value: float) -> str:
    """A stress in Pa, kPa, MPa or GPa."""
    for unit, scale in (("GPa", 1e9), ("MPa", 1e6), ("kPa", 1e3)):
        if value >= scale:
            return f"{value / scale:.3g} {unit}"
    return f"{value:.3g} Pa"


def _advice(p, alpha, lo, hi, within, f_reach, fn, tau, units) -> str:
    """What would make the law reachable: a shear strength (the law's alpha scaled by s,
    tau' = tau / s) where one exists at these loads, and a larger area where its loads
    exceed the cell's."""
    out = []
    if within.any():
        from metainterface.inverse.envelope import TOLERANCE

        slack = TOLERANCE * alpha.max()
        a, low, high = alpha[within], lo[within], hi[within]
        s_lo = float(np.max(low / (a + slack)))
        big = a > slack
        s_hi = float(np.min(high[big] / (a[big] - slack))) if big.any() else math.inf
        if s_lo <= s_hi:
            if units:
                out.append(
                    f"A shear strength tau of {_pa(tau / s_hi)}-{_pa(tau / s_lo)} would reach it "
                    f"(or its friction scaled by {_fmt(s_lo, s_hi)})"
                )
            else:
                out.append(f"Its alpha scaled by {_fmt(s_lo, s_hi)} would reach it")
        else:
            out.append("No single tau/E* fits its shape at these loads: change the law")
    if not within.all():
        grow = float(fn.max() / f_reach)
        out.append(
            f"its largest load needs a {grow:.3g}x larger area"
            if units
            else f"its largest P* is {grow:.3g}x beyond any cell's"
        )
    return "; ".join(out) + "."
