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
"""

from __future__ import annotations

import math
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


def check_scales(named: tuple[tuple[str, object], ...]) -> None:
    """A one-line error for the first (name, value) that is not a finite number > 0."""
    for name, value in named:
        if not (isinstance(value, int | float) and math.isfinite(value) and value > 0):
            raise MetainterfaceError(f"{name} must be finite and > 0, got {value!r}")


def friction_rows(
    normal_force: np.ndarray, friction_force: np.ndarray, source: str, *, loading: bool = False
) -> tuple[np.ndarray, np.ndarray]:
    """A friction test's rows (K,) [N] as float arrays, those with both finite and friction
    > 0 kept; a one-line error for fewer than 3, and (``loading``: a made design's loading
    branch) for a negative load."""
    fn = np.asarray(normal_force, dtype=np.float64)
    ff = np.asarray(friction_force, dtype=np.float64)
    if loading and np.any(fn[np.isfinite(fn)] < 0):
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
    return fn, ff


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

    check_scales((("sphere radius", radius), ("modulus E*", e_star)))
    fn, ff = friction_rows(normal_force, friction_force, source)
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
    x, cost = best.x, float(best.cost)
    # Without adhesion friction is linear in tau, so the best fit on the bound w = 0 has a
    # closed form; the solver stops short of it there (friction grows as sqrt(w): a test
    # without adhesion read tau 1e-6 off, w 5e-14 with scipy 1.17). Kept where it fits
    # better; the covariance is the solver's, next to it.
    ratio = sphere_friction(fn, tau0, 0.0, radius, e_star) / ff
    if np.all(np.isfinite(ratio)) and np.sum(ratio**2) > 0:
        plain = np.array([float(np.sum(ratio) / np.sum(ratio**2)), 0.0])
        plain_cost = 0.5 * float(np.sum(residual(plain) ** 2))
        if plain_cost < cost:
            x, cost = plain, plain_cost
    dof = max(fn.size - 2, 1)
    s2 = 2.0 * cost / dof
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
        residual_rms=float(math.sqrt(2.0 * cost / fn.size)),
        radius=float(radius),
        e_star=float(e_star),
    )
