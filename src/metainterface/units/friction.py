"""Friction-law targets: a measured or wished friction curve -> the dimensionless alpha(P*).

Bowden and Tabor: the static friction force is the interface shear strength times the real
contact area, F_f = tau A_real (paper sec. 2.3). For an interface of nominal area A (the
whole tiled surface) and equivalent modulus E*:

    alpha = A_real / A = F_f / (tau A),      P* = F_n / (A E*).

The curve comes from a CSV with a header and one row per load, in newtons:
``normal_force,friction_force`` or ``normal_force,friction_coefficient`` (F_f = mu F_n); a
header may give the force unit (``normal_force [mN]``), and the file may be separated by ';'
or tabs with decimal commas (:func:`metainterface._files.columns.read_table`).
With tau > 0, A_real and so F_f can only grow with the load: a friction force that decreases
as the load increases, friction at zero load (without adhesion) or a real area larger
than the nominal one is an error naming the row.

With a work of adhesion w [J/m^2] (``work_of_adhesion``) the asperities are JKR contacts
(``physics.adhesion``): the real area, and so friction, is finite at zero load, and an
offset law F_f(0) > 0 is accepted and kept by the fit. The design then uses the forward
model with ``adhesion = w / (E* R)`` (``FrictionTarget.adhesion``).
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from metainterface._names import FIT_NAMES
from metainterface.errors import MetainterfaceError
from metainterface.physics.cell import CellSettings
from metainterface.units._lawfit import LawFit, fit_law
from metainterface.units.law_file import (
    FrictionLaw,
    check_law,
    check_values,
    read_friction_csv,
    zero_load_friction,
)

#: Points a target needs (the design command's minimum), the added origin included.
MIN_POINTS = 3
#: When the measured rows are replaced by a monotone fit (:mod:`._lawfit`): "auto" fits
#: rows that are not a law as they stand (unsorted, repeated loads, friction that falls
#: with scatter) or fewer than FIT_BELOW_ROWS of them; "always" and "never" force it.
FIT_CHOICES = FIT_NAMES
#: Under fit="auto", a valid law of FIT_MIN_ROWS to FIT_BELOW_ROWS - 1 rows is fitted:
#: straight lines between a handful of points make a target with kinks that no smooth
#: contact curve follows (fewer rows are too few to fit a curve to; they are kept).
FIT_BELOW_ROWS = 10
FIT_MIN_ROWS = 5
#: Without adhesion a fit pins the friction at zero load to 0; rows with more than this share
#: of their largest friction there are refused instead (the reach test's tolerance: less is
#: within the curve error's scale, e.g. a sensor's offset).
ZERO_LOAD_SHARE = 0.05


def friction_to_alpha(
    normal_force: np.ndarray,
    friction_force: np.ndarray,
    *,
    shear_strength: float,
    e_star: float,
    area: float,
) -> tuple[np.ndarray, np.ndarray]:
    """(P*, alpha) from loads and friction forces (K,) [N]: P* = F_n/(A E*), alpha = F_f/(tau A).

    shear_strength tau [Pa], e_star E* [Pa], area A: nominal area of the whole interface [m^2].
    """
    fn = np.asarray(normal_force, dtype=np.float64)
    ff = np.asarray(friction_force, dtype=np.float64)
    return fn / (area * e_star), ff / (shear_strength * area)


def alpha_to_friction(
    p_star: np.ndarray,
    alpha: np.ndarray,
    *,
    shear_strength: float,
    e_star: float,
    area: float,
) -> tuple[np.ndarray, np.ndarray]:
    """(F_n, F_f) [N] from a dimensionless curve (K,): the inverse of :func:`friction_to_alpha`."""
    p = np.asarray(p_star, dtype=np.float64)
    a = np.asarray(alpha, dtype=np.float64)
    return p * area * e_star, a * shear_strength * area


def friction_columns(
    p_star: np.ndarray,
    alpha: np.ndarray,
    *,
    shear_strength: float,
    e_star: float,
    area: float,
) -> dict[str, np.ndarray]:
    """Report columns normal_force, friction_force [N] and friction_coefficient (NaN at 0 load)."""
    fn, ff = alpha_to_friction(
        p_star, alpha, shear_strength=shear_strength, e_star=e_star, area=area
    )
    with np.errstate(divide="ignore", invalid="ignore"):
        mu = np.where(fn > 0, ff / np.where(fn > 0, fn, 1.0), np.nan)
    return {"normal_force": fn, "friction_force": ff, "friction_coefficient": mu}


@dataclass(frozen=True)
class FrictionTarget:
    """A friction law turned into the dimensionless target of the design step.

    p_star, alpha: (K,) the target curve, P* strictly increasing from 0. law: the curve in
    newtons (with the origin if it was added). shear_strength tau [Pa], e_star E* [Pa],
    radius R [m], area: nominal area of the whole interface [m^2]. n_cells: area / (L R)^2,
    unit cells that tile it (L from ``settings``).
    """

    p_star: np.ndarray
    alpha: np.ndarray
    law: FrictionLaw
    shear_strength: float
    e_star: float
    radius: float
    area: float
    n_cells: float
    settings: CellSettings = field(default_factory=CellSettings)
    fit: LawFit | None = None
    work_of_adhesion: float = 0.0
    # the zero-load row F_f(0) > 0 was extrapolated from the first two (the law began above
    # zero load), not given
    offset_extrapolated: bool = False

    @property
    def adhesion(self) -> float:
        """w / (E* R): the work of adhesion in the core's units (``Independent(adhesion=)``)."""
        return self.work_of_adhesion / (self.e_star * self.radius)

    def columns(self) -> dict[str, np.ndarray]:
        """{'p_star', 'alpha'}: the target as the design command's CSV columns."""
        return {"p_star": self.p_star, "alpha": self.alpha}

    def record(self) -> dict[str, Any]:
        """JSON-ready description in SI, for design.json and provenance."""
        return {
            "source": self.law.source,
            "shear_strength_pa": self.shear_strength,
            "e_star_pa": self.e_star,
            "radius_m": self.radius,
            "area_m2": self.area,
            "n_cells": self.n_cells,
            "normal_force_n": [float(v) for v in self.law.normal_force],
            "friction_force_n": [float(v) for v in self.law.friction_force],
            **({} if self.fit is None else {"fit": fit_record(self.fit)}),
            **(
                {"work_of_adhesion_j_m2": self.work_of_adhesion, "adhesion": self.adhesion}
                if self.work_of_adhesion
                else {}
            ),
            **({"offset": "extrapolated"} if self.offset_extrapolated else {}),
        }


def fit_record(fit: LawFit) -> dict[str, Any]:
    """JSON-ready description of a law fit: the method, its residual and the raw data [N]."""
    return {
        "method": "monotone cubic B-spline, knots by GCV",
        "interior_knots": fit.interior_knots,
        "residual_rms_n": fit.residual_rms,
        "relative_residual": fit.relative_residual,
        "raw_normal_force_n": [float(v) for v in fit.raw_normal],
        "raw_friction_force_n": [float(v) for v in fit.raw_friction],
        "summary": fit.summary(),
    }


def prepare_law(
    law: FrictionLaw | str | os.PathLike[str], fit: str = "auto", *, offset: bool = False
) -> tuple[FrictionLaw, LawFit | None]:
    """The law to design for, and the fit when the rows were replaced by one.

    fit: "auto" (fit rows that are not a law as they stand, or 5 to 9 rows of a law),
    "always" or "never" (the rows must then be a law). offset (adhesion): friction at zero
    load is allowed, and fitted rather than pinned at 0.
    """
    if fit not in FIT_CHOICES:
        raise MetainterfaceError(f"fit must be one of {', '.join(FIT_CHOICES)}, got {fit!r}")
    if not isinstance(law, FrictionLaw):
        law = read_friction_csv(law, check=False)
    if fit == "never":
        check_law(law, offset=offset)
        return law, None
    if fit == "auto":
        try:
            check_law(law, offset=offset)
        except MetainterfaceError:
            pass
        else:
            if not FIT_MIN_ROWS <= law.normal_force.size < FIT_BELOW_ROWS:
                return law, None
    check_values(law.source, "normal_force", law.normal_force)
    check_values(law.source, "friction_force", law.friction_force)
    if not offset:
        _no_adhesive_offset(law)
    loads = np.unique(law.normal_force[law.normal_force > 0])
    if loads.size < MIN_POINTS:
        raise MetainterfaceError(
            f"{law.source}: fitting a law needs at least {MIN_POINTS} distinct positive normal "
            f"forces, got {loads.size}"
        )
    lf = fit_law(law.normal_force, law.friction_force, offset=offset)
    fn, ff = lf.sample()
    fitted = FrictionLaw(
        normal_force=fn, friction_force=ff, rows=np.arange(fn.size), source=law.source
    )
    return fitted, lf


def _no_adhesive_offset(law: FrictionLaw) -> None:
    """Refuse rows whose friction at zero load is above ZERO_LOAD_SHARE of the largest: a
    fit without adhesion pins F_f(0) at 0, and would design another law than the one
    measured there without a word. A smaller one (a sensor's offset) is fitted away."""
    at_zero = np.flatnonzero(law.normal_force == 0)
    if not at_zero.size:
        return
    k = int(at_zero[np.argmax(law.friction_force[at_zero])])
    top = float(np.max(law.friction_force))
    if law.friction_force[k] > ZERO_LOAD_SHARE * top:
        share = f" ({100 * law.friction_force[k] / top:.3g} % of the largest)"
        raise MetainterfaceError(zero_load_friction(law, k, share))


def friction_target(
    law: FrictionLaw | str | os.PathLike[str],
    *,
    shear_strength: float,
    e_star: float,
    radius: float,
    area: float,
    settings: CellSettings | None = None,
    include_origin: bool = True,
    fit: str = "auto",
    work_of_adhesion: float = 0.0,
) -> FrictionTarget:
    """Convert a friction law (a FrictionLaw or a CSV path) into the alpha(P*) target.

    shear_strength tau [Pa], e_star E* [Pa], radius R [m], area: nominal area of the whole
    interface [m^2], all > 0 (parse them with ``units.quantities``). settings: the cell
    (default: the paper's), used for L. include_origin: prepend (0 N, 0 N) when the first load
    is > 0 (F_f = tau A_real vanishes with the load). fit: "auto", "always" or "never",
    when the rows are replaced by a monotone smooth fit (:func:`prepare_law`; the fit is
    kept in ``fit``). work_of_adhesion w [J/m^2] >= 0: with w > 0 friction at zero load is
    accepted and kept, and the origin added is (0 N, F_f(0)), F_f(0) extrapolated linearly
    from the first two rows (floored at 0). Errors name the row.
    """
    from metainterface.physics.jkr import ADHESION_LIMIT

    settings = settings or CellSettings()
    for name, value in (
        ("shear strength", shear_strength),
        ("modulus E*", e_star),
        ("radius", radius),
        ("area", area),
    ):
        if not (math.isfinite(value) and value > 0):
            raise MetainterfaceError(f"{name} must be finite and > 0, got {value!r}")
    w = float(work_of_adhesion)
    if not (math.isfinite(w) and 0 <= w <= ADHESION_LIMIT * e_star * radius):
        raise MetainterfaceError(
            f"work of adhesion must be in [0, {ADHESION_LIMIT * e_star * radius:g}] J/m^2 "
            f"(up to {ADHESION_LIMIT:g} E* R), got {work_of_adhesion!r}",
            argument="work_of_adhesion",
        )
    law, lf = prepare_law(law, fit, offset=w > 0)
    extrapolated = False
    if include_origin and law.normal_force[0] > 0:
        f0 = 0.0
        if w > 0 and law.normal_force.size >= 2:  # the offset, extrapolated
            fn, ff = law.normal_force, law.friction_force
            slope = (ff[1] - ff[0]) / (fn[1] - fn[0])
            f0 = float(min(max(ff[0] - slope * fn[0], 0.0), ff[0]))
            extrapolated = f0 > 0
        law = FrictionLaw(
            normal_force=np.concatenate([[0.0], law.normal_force]),
            friction_force=np.concatenate([[f0], law.friction_force]),
            rows=np.concatenate([[0], law.rows]),
            source=law.source,
        )
    if law.normal_force.size < MIN_POINTS:
        raise MetainterfaceError(
            f"{law.source}: a target needs at least {MIN_POINTS} points (origin included), "
            f"got {law.normal_force.size}"
        )
    cell_area = (settings.cell_side / settings.radius * radius) ** 2
    if area < cell_area:
        raise MetainterfaceError(
            f"area {area:g} m^2 is smaller than one unit cell (L R)^2 = {cell_area:g} m^2; "
            f"give a larger --area or a smaller --radius"
        )
    p_star, alpha = friction_to_alpha(
        law.normal_force,
        law.friction_force,
        shear_strength=shear_strength,
        e_star=e_star,
        area=area,
    )
    over = np.flatnonzero(alpha >= 1)
    if over.size:
        k = int(over[0])
        raise MetainterfaceError(
            f"{law.source}: row {law.rows[k]}: friction {law.friction_force[k]:g} N needs a real "
            f"contact area F_f / tau = {law.friction_force[k] / shear_strength:g} m^2, not below "
            f"the nominal area {area:g} m^2 (alpha = {alpha[k]:.3g}); check --shear-strength "
            f"and --area"
        )
    return FrictionTarget(
        p_star=p_star,
        alpha=alpha,
        law=law,
        shear_strength=float(shear_strength),
        e_star=float(e_star),
        radius=float(radius),
        area=float(area),
        n_cells=area / cell_area,
        settings=settings,
        fit=lf,
        work_of_adhesion=w,
        offset_extrapolated=extrapolated,
    )


def friction_target_from_options(
    path: str | os.PathLike[str],
    *,
    shear_strength: str | None,
    modulus: str | None,
    radius: str | None,
    area: str | None,
    settings: CellSettings | None = None,
    fit: str = "auto",
    work_of_adhesion: str | None = None,
) -> FrictionTarget:
    """:func:`friction_target` from command-line strings with units ('0.25MPa', '4cm2').

    Errors name the options --friction-csv, --shear-strength, --modulus, --radius, --area.
    """
    given = {
        "--shear-strength": shear_strength,
        "--modulus": modulus,
        "--radius": radius,
        "--area": area,
    }
    missing = [name for name, value in given.items() if value is None]
    if missing:
        raise MetainterfaceError(
            f"--friction-csv needs --shear-strength, --modulus, --radius and --area "
            f"(missing {', '.join(missing)})"
        )
    return friction_target_in_units(
        path,
        shear_strength=shear_strength,
        modulus=modulus,
        radius=radius,
        area=area,
        settings=settings,
        fit=fit,
        options=True,
        work_of_adhesion=work_of_adhesion,
    )


def friction_target_in_units(
    law: FrictionLaw | str | os.PathLike[str],
    *,
    shear_strength: str | float,
    modulus: str | float,
    radius: str | float,
    area: str | float,
    settings: CellSettings | None = None,
    fit: str = "auto",
    options: bool = False,
    work_of_adhesion: str | float | None = None,
) -> FrictionTarget:
    """:func:`friction_target` from quantities with units ('0.25MPa', '0.5mm', '4cm2') or
    numbers in SI. A bad quantity's error names its argument (``shear_strength``), or with
    ``options`` the command-line option (``--shear-strength``); a likely unit slip
    (:mod:`.plausible`) warns."""
    from metainterface.units.plausible import warn_unit_slips
    from metainterface.units.quantities import (
        parse_area,
        parse_length,
        parse_pressure,
        parse_work_of_adhesion,
    )

    def name(arg: str) -> str:
        return "--" + arg.replace("_", "-") if options else arg

    tau = parse_pressure(shear_strength, option=name("shear_strength"))
    e_star = parse_pressure(modulus, option=name("modulus"))
    r = parse_length(radius, option=name("radius"))
    a = parse_area(area, option=name("area"))
    w = 0.0
    if work_of_adhesion is not None:
        w = parse_work_of_adhesion(work_of_adhesion, option=name("work_of_adhesion"))
    warn_unit_slips(modulus=e_star, shear_strength=tau, radius=r, work_of_adhesion=w)
    return friction_target(
        law,
        shear_strength=tau,
        e_star=e_star,
        radius=r,
        area=a,
        settings=settings,
        fit=fit,
        work_of_adhesion=w,
    )
