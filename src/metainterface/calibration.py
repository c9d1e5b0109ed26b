"""Calibrate the interface from a friction test of one sphere: tau and w (issue 38).

Few users know their interface shear strength tau or work of adhesion w. A sphere of
radius R slid on the material at a few normal forces F_n gives both: with Bowden-Tabor
friction F_f = tau A_real and a JKR contact (Johnson, Kendall & Roberts 1971),

    F_f = tau pi a(F_n)^2,
    a^3 = (R / K) (F_n + 3 pi w R + sqrt(6 pi w R F_n + (3 pi w R)^2)),   K = 4 E* / 3,

valid for F_n >= -3/2 pi w R (pull-off). E* and R are known (--modulus, --sphere-radius);
tau and w are fitted by least squares on the relative residuals (F_f,model / F_f - 1: a
friction test's scatter is proportional to the force), w >= 0. Their standard errors come
from the fit's covariance s^2 (J^T J)^-1, s^2 the residual variance; ``interval`` gives
the 95 % ranges (Student's t). w = 0 is the Hertz contact (no offset): a test whose
friction vanishes with the load gives w ~ 0 within its uncertainty.
The result feeds ``--shear-strength`` and ``--work-of-adhesion`` of ``design``.

Or from a friction test of a made design (:func:`calibrate_design`): its cell (gammas and
heights of its design.json, R and the patch's nominal area A from its physical block) under
the adhesive model in load control (``Independent(adhesion=w / (E* R))``, the curve the
design was made with), F_f = tau alpha(F_n / (A E*); w) A. tau enters linearly, so for each
w the best tau is closed-form; w is found by a scan over log w then a bounded 1-D search,
and the uncertainty is the same s^2 (J^T J)^-1 (J in w by central differences).
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass
from typing import Any

import numpy as np

from metainterface.errors import MetainterfaceError


def jkr_contact_radius(
    normal_force: np.ndarray, work: float, radius: float, e_star: float
) -> np.ndarray:
    """JKR contact radius a [m] of a sphere of radius R [m] under F_n (K,) [N], w [J/m^2],
    E* [Pa]; NaN below the pull-off force -3/2 pi w R."""
    f = np.asarray(normal_force, dtype=np.float64)
    q = 3.0 * math.pi * work * radius
    inside = 6.0 * math.pi * work * radius * f + q * q
    with np.errstate(invalid="ignore"):
        cube = radius / (4.0 * e_star / 3.0) * (f + q + np.sqrt(inside))
    return np.where(inside >= 0, np.cbrt(cube), np.nan)


def sphere_friction(
    normal_force: np.ndarray, tau: float, work: float, radius: float, e_star: float
) -> np.ndarray:
    """F_f = tau pi a^2 [N] of a JKR sphere contact at F_n (K,) [N]."""
    return tau * math.pi * jkr_contact_radius(normal_force, work, radius, e_star) ** 2


@dataclass(frozen=True)
class Calibration:
    """tau [Pa] and w [J/m^2] fitted to a sphere friction test, with standard errors.

    tau_sigma, work_sigma: standard errors; covariance: (2, 2) of (tau, w); rows: data
    points used; residual_rms: rms relative residual; radius [m], e_star [Pa]: as given.
    contact: what was tested, for the summary ("JKR sphere", or the design's cell with its
    area); area: the nominal area of a made design's patch [m^2] (0 for a sphere).
    """

    tau: float
    work: float
    tau_sigma: float
    work_sigma: float
    covariance: np.ndarray
    rows: int
    residual_rms: float
    radius: float
    e_star: float
    contact: str = "JKR sphere"
    area: float = 0.0

    def interval(self, level: float = 0.95) -> dict[str, tuple[float, float]]:
        """{'tau': (lo, hi), 'work': (lo, hi)}: the two-sided ``level`` ranges (Student's t
        with rows - 2 degrees of freedom); w's floored at 0."""
        from scipy.stats import t as student

        k = float(student.ppf(0.5 + level / 2.0, max(self.rows - 2, 1)))
        return {
            "tau": (self.tau - k * self.tau_sigma, self.tau + k * self.tau_sigma),
            "work": (max(self.work - k * self.work_sigma, 0.0), self.work + k * self.work_sigma),
        }

    def options(self) -> str:
        """The design options this calibration gives: --shear-strength and --work-of-adhesion."""
        return (
            f"--shear-strength {self.tau / 1e3:.4g}kPa "
            f"--work-of-adhesion {self.work * 1e3:.4g}mJ/m2"
        )

    def summary(self) -> list[str]:
        """Lines for a person: the values, their uncertainty, the options to use."""
        ci = self.interval()
        return [
            f"tau = {self.tau / 1e3:.4g} kPa +- {self.tau_sigma / 1e3:.2g} kPa "
            f"(95 %: {ci['tau'][0] / 1e3:.4g}-{ci['tau'][1] / 1e3:.4g} kPa)",
            f"w   = {self.work * 1e3:.4g} mJ/m^2 +- {self.work_sigma * 1e3:.2g} mJ/m^2 "
            f"(95 %: {ci['work'][0] * 1e3:.4g}-{ci['work'][1] * 1e3:.4g} mJ/m^2)",
            f"fit: {self.rows} rows, rms relative residual {100 * self.residual_rms:.2g} % "
            f"({self.contact}, R = {self.radius * 1e3:.4g} mm, E* = {self.e_star / 1e6:.4g} MPa"
            + (f", area {self.area * 1e4:.4g} cm^2)" if self.area else ")"),
            f"use: {self.options()}",
        ]

    def record(self) -> dict[str, Any]:
        """JSON-ready, SI."""
        ci = self.interval()
        return {
            "model": "JKR sphere, F_f = tau pi a^2"
            if not self.area
            else f"{self.contact}, F_f = tau alpha A (adhesive model, load control)",
            "shear_strength_pa": self.tau,
            "shear_strength_sigma_pa": self.tau_sigma,
            "work_of_adhesion_j_m2": self.work,
            "work_of_adhesion_sigma_j_m2": self.work_sigma,
            "covariance": self.covariance.tolist(),
            "interval_95": {k: list(v) for k, v in ci.items()},
            "rows": self.rows,
            "residual_rms_relative": self.residual_rms,
            "sphere_radius_m" if not self.area else "radius_m": self.radius,
            "e_star_pa": self.e_star,
            **({"area_m2": self.area} if self.area else {}),
            "options": self.options(),
        }


def calibrate_sphere(
    normal_force: np.ndarray,
    friction_force: np.ndarray,
    *,
    radius: float,
    e_star: float,
    source: str = "friction test",
) -> Calibration:
    """Fit tau and w to a sphere's friction test (K,) [N], radius R [m], E* [Pa].

    Needs at least 3 rows with friction > 0, loads finite (negative ones, a pull, allowed).
    """
    from scipy.optimize import least_squares

    for name, value in (("sphere radius", radius), ("modulus E*", e_star)):
        if not (isinstance(value, int | float) and math.isfinite(value) and value > 0):
            raise MetainterfaceError(f"{name} must be finite and > 0, got {value!r}")
    fn = np.asarray(normal_force, dtype=np.float64)
    ff = np.asarray(friction_force, dtype=np.float64)
    keep = np.isfinite(fn) & np.isfinite(ff) & (ff > 0)
    fn, ff = fn[keep], ff[keep]
    if fn.size < 3:
        raise MetainterfaceError(
            f"{source}: calibrating tau and w needs at least 3 rows with friction > 0, "
            f"got {fn.size}"
        )
    # scales: tau from the largest load's Hertz area; w from the force scale F / (pi R)
    a_top = jkr_contact_radius(np.array([max(fn.max(), 1e-300)]), 0.0, radius, e_star)[0]
    tau0 = float(ff.max() / (math.pi * a_top**2)) if a_top > 0 else 1.0
    w_scale = max(float(np.abs(fn).max()), 1e-300) / (math.pi * radius)

    def residual(x: np.ndarray) -> np.ndarray:
        model = sphere_friction(fn, x[0] * tau0, x[1] * w_scale, radius, e_star)
        return np.where(np.isfinite(model), model / ff - 1.0, 10.0)

    best = None
    for w_start in (0.0, 0.01, 0.1, 1.0):  # the fit is not convex in w: a few starts
        sol = least_squares(
            residual,
            x0=[1.0, w_start],
            bounds=([1e-12, 0.0], [np.inf, np.inf]),
            method="trf",
            xtol=1e-14,
            ftol=1e-14,
            gtol=1e-14,
        )
        if best is None or sol.cost < best.cost:
            best = sol
    assert best is not None
    x = best.x
    dof = max(fn.size - 2, 1)
    s2 = 2.0 * best.cost / dof
    jac = best.jac / np.array([tau0, w_scale])[None]  # d residual / d (tau, w)
    try:
        cov = np.linalg.inv(jac.T @ jac) * s2
    except np.linalg.LinAlgError:
        cov = np.full((2, 2), np.inf)
    tau, work = float(x[0] * tau0), float(x[1] * w_scale)
    return Calibration(
        tau=tau,
        work=work,
        tau_sigma=float(math.sqrt(max(cov[0, 0], 0.0))),
        work_sigma=float(math.sqrt(max(cov[1, 1], 0.0))),
        covariance=cov,
        rows=int(fn.size),
        residual_rms=float(math.sqrt(2.0 * best.cost / fn.size)),
        radius=float(radius),
        e_star=float(e_star),
    )


def calibrate_csv(
    path: str | os.PathLike[str],
    *,
    modulus: str | float,
    sphere_radius: str | float | None = None,
    design: str | os.PathLike[str] | None = None,
    area: str | float | None = None,
    radius: str | float | None = None,
) -> Calibration:
    """tau and w from a friction CSV (``normal_force,friction_force`` [N], or
    ``normal_force,friction_coefficient``; units in the header), quantities with units.

    Either a sphere test (``sphere_radius``: :func:`calibrate_sphere`) or a made design's
    (``design``, a design.json: :func:`calibrate_design`), whose physical block gives R and
    the patch's nominal area; ``area`` and ``radius`` give or override them.
    """
    from metainterface.units.friction import read_friction_csv
    from metainterface.units.quantities import parse_area, parse_length, parse_pressure

    if (sphere_radius is None) == (design is None):
        raise MetainterfaceError(
            "calibrate a sphere test (--sphere-radius) or a made design's (--design), one of them",
            argument="--design",
        )
    e = parse_pressure(modulus, option="--modulus")
    law = read_friction_csv(path, check=False)
    if sphere_radius is not None:
        if area is not None or radius is not None:
            raise MetainterfaceError(
                "--area and --radius are for a made design (--design); a sphere takes "
                "--sphere-radius",
                argument="--area" if area is not None else "--radius",
            )
        r = parse_length(sphere_radius, option="--sphere-radius")
        return calibrate_sphere(
            law.normal_force, law.friction_force, radius=r, e_star=e, source=str(path)
        )
    from metainterface.physics.cell import Design

    d = Design.load(design)
    block = d.extras.get("physical") if isinstance(d.extras.get("physical"), dict) else {}
    if radius is None and "radius_m" not in block:
        raise MetainterfaceError(
            f"{design}: no physical block with the radius: give --radius", argument="--radius"
        )
    if area is None and "area_m2" not in block:
        raise MetainterfaceError(
            f"{design}: no physical block with the patch's area: give --area", argument="--area"
        )
    r = parse_length(radius, option="--radius") if radius is not None else block["radius_m"]
    a = parse_area(area, option="--area") if area is not None else block["area_m2"]
    return calibrate_design(
        law.normal_force,
        law.friction_force,
        d,
        e_star=e,
        area=float(a),
        radius=float(r),
        source=str(path),
    )


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


def design_friction(
    normal_force: np.ndarray,
    tau: float,
    work: float,
    design: Any,
    *,
    e_star: float,
    area: float,
    radius: float,
) -> np.ndarray:
    """F_f = tau alpha(P*) A [N] of a made design's patch at loads F_n (K,) >= 0 [N].

    design: a Design (its gammas and heights in units of R); e_star E* [Pa]; area: the
    patch's nominal area A [m^2]; radius R [m]; work w [J/m^2]. alpha is the adhesive
    model's loading curve under a rising force (``Independent(adhesion=w / (E* R))``) at
    P* = F_n / (A E*); at zero load, the state just after the cell snaps in.
    """
    import torch

    from metainterface.physics.models import Independent

    fn = np.asarray(normal_force, dtype=np.float64)
    p = fn / (area * e_star)
    q = np.maximum(p, 1e-12 * max(float(p.max()), 1e-300))  # zero load: after the snap-in
    model = Independent(adhesion=work / (e_star * radius))
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
) -> Calibration:
    """Fit tau and w to a friction test (K,) [N] of a made design's patch.

    design: the Design made; e_star E* [Pa]; area: the patch's nominal area [m^2]; radius:
    the asperity radius R [m]. Loads must be >= 0 (the loading branch: a pull depends on
    the path the patch came by); rows with friction <= 0 are left out; at least 3 rows.
    """
    from metainterface.physics.adhesion import ADHESION_LIMIT

    for name, value in (("modulus E*", e_star), ("area", area), ("radius", radius)):
        if not (isinstance(value, int | float) and math.isfinite(value) and value > 0):
            raise MetainterfaceError(f"{name} must be finite and > 0, got {value!r}")
    fn = np.asarray(normal_force, dtype=np.float64)
    ff = np.asarray(friction_force, dtype=np.float64)
    if np.any(fn[np.isfinite(fn)] < 0):
        raise MetainterfaceError(
            f"{source}: a made design's calibration takes loads >= 0 (the loading branch), "
            f"got {float(np.nanmin(fn)):g} N"
        )
    keep = np.isfinite(fn) & np.isfinite(ff) & (ff > 0)
    fn, ff = fn[keep], ff[keep]
    if fn.size < 3:
        raise MetainterfaceError(
            f"{source}: calibrating tau and w needs at least 3 rows with friction > 0, "
            f"got {fn.size}"
        )
    unit = e_star * radius  # w [J/m^2] = w [E* R] * unit

    def shape(w: float) -> np.ndarray:  # friction per unit tau, over the measured friction
        return design_friction(fn, 1.0, w, design, e_star=e_star, area=area, radius=radius) / ff

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
    return Calibration(
        tau=tau,
        work=work,
        tau_sigma=tau_sigma,
        work_sigma=work_sigma,
        covariance=cov,
        rows=int(fn.size),
        residual_rms=float(math.sqrt(cost / fn.size)),
        radius=float(radius),
        e_star=float(e_star),
        contact=f"the cell of {name}, JKR asperities",
        area=float(area),
    )
