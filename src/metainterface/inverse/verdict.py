"""``reachability``: can a cell follow this friction law, at this E*, tau and area?

The answer comes from the one reach test (:mod:`metainterface.inverse.envelope`, which
``feasible_scale`` and ``design`` ask too, with or without adhesion) and is told in friction
terms: the law's friction coefficient mu = F_f / F_n against the mu a cell reaches at its
loads, mu = (alpha / P*) (tau / E*), and what tau or area would make it reachable.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass
from typing import Any

import numpy as np

from metainterface._threads import uses_threads
from metainterface.errors import MetainterfaceError, UnreachableError
from metainterface.inverse.envelope import TOLERANCE, reach_violation, reachable_envelope
from metainterface.inverse.targets import Target
from metainterface.physics.cell import CellSettings
from metainterface.units.friction import FrictionLaw, friction_target_in_units


@uses_threads()
def reachability(
    law: Target | FrictionLaw | str | os.PathLike[str],
    *,
    shear_strength: str | float | None = None,
    modulus: str | float | None = None,
    area: str | float | None = None,
    radius: str | float = "1mm",
    settings: CellSettings | None = None,
    work_of_adhesion: str | float | None = None,
) -> Reachability:
    """Whether cells of ``settings`` (default: the paper's) can follow a friction law.

    Parameters
    ----------
    law : Target, FrictionLaw or path
        A target (one made by ``Target.from_friction`` carries its tau, E* and area; any
        other is tested in alpha/P* terms), a FrictionLaw or a friction CSV
        (``normal_force,friction_force`` [N] or ``normal_force,friction_coefficient``).
    shear_strength, modulus, area : str or float
        tau, E* and the nominal area ('0.25MPa', '2MPa', '4cm2', or SI), for a law or CSV.
    radius : str or float
        Asperity radius R, only to check the area holds a unit cell (default '1mm').
    settings : CellSettings
        The design space (N, gamma bounds, Delta_max).
    work_of_adhesion : str or float
        w ('50mJ/m2', J/m^2) for adhesive contact (JKR asperities), with a law or CSV (a
        Target carries its own); then R sets w / (E* R) and should be the part's.

    Returns
    -------
    Reachability
        ``.reachable``, the law's ``law_mu``, the ``reachable_mu`` at its loads at this
        tau / E*, the ``load_range`` [N] on this area, and a one- or two-line ``.message``
        saying what would make the law reachable.
    """
    if settings is not None and not isinstance(settings, CellSettings):
        raise MetainterfaceError("settings must be a CellSettings")
    if isinstance(law, Target):
        if any(v is not None for v in (shear_strength, modulus, area)):
            raise MetainterfaceError(
                "a Target carries its own units; give shear_strength, modulus and area "
                "with a friction law or CSV only"
            )
        return targetlaw_reachability(law, settings)
    missing = [
        n
        for n, v in (("shear_strength", shear_strength), ("modulus", modulus), ("area", area))
        if v is None
    ]
    if missing:
        raise MetainterfaceError(
            f"a friction law needs shear_strength, modulus and area (missing {', '.join(missing)})",
            argument=missing[0],
        )
    ft = friction_target_in_units(
        law,
        shear_strength=shear_strength,
        modulus=modulus,
        radius=radius,
        area=area,
        settings=settings,
        work_of_adhesion=work_of_adhesion,
    )
    return law_reachability(
        ft.law.normal_force,
        ft.law.friction_force,
        shear_strength=ft.shear_strength,
        e_star=ft.e_star,
        area=ft.area,
        settings=settings,
        adhesion=ft.adhesion,
    )


def targetlaw_reachability(target: Target, settings: CellSettings | None = None) -> Reachability:
    """The reachability of a target: in friction terms when it came from a friction law
    (its ``meta['friction']`` record), else in alpha/P* terms."""
    f: dict[str, Any] | None = target.meta.get("friction")
    if isinstance(f, dict) and {"shear_strength_pa", "e_star_pa", "area_m2"} <= set(f):
        # the full target holds the law's points (P*, alpha) in the record's units
        e_star, tau, a = f["e_star_pa"], f["shear_strength_pa"], f["area_m2"]
        return law_reachability(
            np.asarray(target.p_star) * a * e_star,
            np.asarray(target.alpha) * tau * a,
            shear_strength=tau,
            e_star=e_star,
            area=a,
            settings=settings,
            adhesion=float(f.get("adhesion", 0.0) or 0.0),
        )
    return law_reachability(target.p_star, target.alpha, settings=settings, units=False)


def refuse_unreachable(
    targets: list[Target], settings: CellSettings | None, force: bool
) -> dict[str, Reachability]:
    """The reachability of each friction-law target; an UnreachableError for the first one
    out of reach unless ``force``. Targets without a friction law are not refused (their
    envelope warnings stay in the notes)."""
    out = {}
    for t in targets:
        if "friction" not in t.meta:
            continue
        r = targetlaw_reachability(t, settings)
        out[t.name] = r
        if not r.reachable and not force:
            one_line = r.message.replace("\n", " ")
            raise UnreachableError(
                f"friction law {t.name}: {one_line} force=True designs the closest cell anyway.",
                reachability=r,
                target=t.name,
            )
    return out


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


def law_reachability(
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
        slack = TOLERANCE * alpha.max()
        a, low, high = alpha[within], lo[within], hi[within]
        s_lo = float(np.max(low / (a + slack)))
        big = a > slack
        s_hi = float(np.min(high[big] / (a[big] - slack))) if big.any() else math.inf
        if s_lo <= s_hi and not math.isfinite(s_hi):  # no upper bound on the scaling
            if units:
                out.append(
                    f"A shear strength tau of at most {_pa(tau / s_lo)} would reach it "
                    f"(or its friction scaled by {s_lo:.3g} or more)"
                )
            else:
                out.append(f"Its alpha scaled by {s_lo:.3g} or more would reach it")
        elif s_lo <= s_hi:
            if units:
                out.append(
                    f"A shear strength tau of {_pa(tau / s_hi)}-{_pa(tau / s_lo)} would reach it "
                    f"(or its friction scaled by {_fmt(s_lo, s_hi)})"
                )
            else:
                out.append(f"Its alpha scaled by {_fmt(s_lo, s_hi)} would reach it")
        else:
            out.append("No single tau/E* fits its shape at these loads: change the law")
    if not within.all() and not f_reach > 0:  # no cell carries any load: no factor says it
        out.append(
            "no cell of this family carries any of its load at this scale"
            if units
            else "no cell of this family carries any of its P*"
        )
    elif not within.all():
        grow = float(fn.max() / f_reach)
        out.append(
            f"its largest load needs a {grow:.3g}x larger area"
            if units
            else f"its largest P* is {grow:.3g}x beyond any cell's"
        )
    return "; ".join(out) + "."
