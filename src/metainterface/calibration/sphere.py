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

from metainterface.calibration.refuse import refuse
from metainterface.errors import MetainterfaceError


def jkr_contact_radius(
    normal_force: np.ndarray, work: float, radius: float, e_star: float
) -> np.ndarray:
    """JKR contact radius a [m] of a sphere of radius R [m] under F_n (K,) [N], w [J/m^2],
    E* [Pa]; NaN below the pull-off force -3/2 pi w R."""
    f = np.asarray(normal_force, dtype=np.float64)
    q = 3.0 * math.pi * work * radius
    inside = 6.0 * math.pi * work * radius * f + q * q
    # at pull-off inside is 0 but for rounding: a relative 1e-9 below it is pull-off
    inside = np.where(inside >= -1e-9 * q * q, np.maximum(inside, 0.0), inside)
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
    rows counts the measured pull-off force as one where the fit used it.
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
    #: w's least possible value [J/m^2]: a pull the test held (the contact had let go at
    #: any smaller w); the 95 % range does not go below it.
    work_floor: float = 0.0
    #: The measured pull-off force [N] the fit used (None: none given).
    pull_off: float | None = None
    #: The 95 % ranges of the profile likelihood, {'tau': (lo, hi), 'work': (lo, hi)}
    #: (w's not floored; None: from the standard errors).
    ranges: dict[str, tuple[float, float]] | None = None

    def interval(
        self, level: float = 0.95, *, floored: bool = True
    ) -> dict[str, tuple[float, float]]:
        """{'tau': (lo, hi), 'work': (lo, hi)}: the two-sided ``level`` ranges (Student's t
        with rows - 2 degrees of freedom); w's floored at ``work_floor`` (>= 0) unless
        ``floored`` is False."""
        from scipy.stats import t as student

        k = float(student.ppf(0.5 + level / 2.0, max(self.rows - 2, 1)))
        tau = (self.tau - k * self.tau_sigma, self.tau + k * self.tau_sigma)
        work = (self.work - k * self.work_sigma, self.work + k * self.work_sigma)
        if self.ranges is not None and abs(level - 0.95) < 1e-12:
            tau, work = self.ranges["tau"], self.ranges["work"]
        lo = max(work[0], self.work_floor) if floored else work[0]
        return {"tau": tau, "work": (lo, work[1])}

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
            *(
                [f"pull-off {self.pull_off * 1e3:.4g} mN used as a row of the fit"]
                if self.pull_off is not None
                else []
            ),
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
            **({"pull_off_n": self.pull_off} if self.pull_off is not None else {}),
            **({"work_of_adhesion_floor_j_m2": self.work_floor} if self.work_floor else {}),
            "options": self.options(),
        }


#: The relative precision of a test's loads (a load cell's resolution, a file's digits): a
#: pull within it beyond a w's pull-off force is read at pull-off, so w's floor from the
#: pulls the test held is that much below the largest pull's w.
LOAD_PRECISION = 1e-3


def check_scales(named: tuple[tuple[str, object], ...]) -> None:
    """A one-line error for the first (name, value) that is not a finite number > 0."""
    for name, value in named:
        if not (isinstance(value, int | float) and math.isfinite(value) and value > 0):
            raise MetainterfaceError(f"{name} must be finite and > 0, got {value!r}")


def friction_rows(
    normal_force: np.ndarray,
    friction_force: np.ndarray,
    source: str,
    *,
    loading: bool = False,
    unit: tuple[str, float] = ("N", 1.0),
) -> tuple[np.ndarray, np.ndarray]:
    """A friction test's rows (K,) [N] as float arrays, those with both finite and friction
    > 0 kept; a one-line error for fewer than 3, and (``loading``: a made design's loading
    branch) for a negative load, in the file's ``unit`` (label, N per unit)."""
    from metainterface.units.law_file import in_unit

    fn = np.asarray(normal_force, dtype=np.float64)
    ff = np.asarray(friction_force, dtype=np.float64)
    if loading and np.any(fn[np.isfinite(fn)] < 0):
        raise MetainterfaceError(
            f"{source}: a made design's calibration takes loads >= 0 (the loading branch), "
            f"got {in_unit(float(np.nanmin(fn)), unit)}"
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
    pull_off: float | None = None,
    unit: tuple[str, float] = ("N", 1.0),
) -> Calibration:
    """Fit tau and w to a sphere's friction test (K,) [N], radius R [m], E* [Pa].

    Needs at least 3 rows with friction > 0, loads finite: pull rows (a negative load, down
    to pull-off) are used, and a pull the sphere held bounds w from below (w >= 2 |F_n| /
    (3 pi R)). ``pull_off``: the measured pull-off force [N] (its magnitude), a further
    residual ln(3/2 pi w R / F_off) weighted as one row. The 95 % ranges are the profile
    likelihood's (``calibration.profile``): a linearised covariance fails where a row sits
    at pull-off, where friction's derivative in w is infinite. Refuses a test the JKR
    model cannot explain (``calibration.refuse``). unit: (label, N per unit) of the file's
    forces, for messages.
    """
    from metainterface.calibration.profile import fit_profile
    from metainterface.units.law_file import in_unit

    check_scales((("sphere radius", radius), ("modulus E*", e_star)))
    fn, ff = friction_rows(normal_force, friction_force, source, unit=unit)
    off = None
    if pull_off is not None:
        check_scales((("pull-off force", abs(float(pull_off))),))
        off = abs(float(pull_off))
    # a pull held: w at least the one whose pull-off it is (else the contact had let go),
    # less the loads' precision (a row at pull-off is read at it)
    floor = max(-float(fn.min()), 0.0) / (1.5 * math.pi * radius) * (1 - LOAD_PRECISION)
    if off is not None and floor > off / (1.5 * math.pi * radius) * (1 + 1e-9):
        raise MetainterfaceError(
            f"{source}: a row pulls {in_unit(-float(fn.min()), unit)}, more than the pull-off "
            f"force {in_unit(off, unit)} given: the sphere would have come off"
        )

    def shape(w: float) -> np.ndarray:  # friction per unit tau over the measured friction
        off_w = -1.5 * math.pi * w * radius
        at = np.where((fn < off_w) & (fn >= off_w * (1 + LOAD_PRECISION)), off_w, fn)
        return sphere_friction(at, 1.0, w, radius, e_star) / ff

    def extra(w: float) -> np.ndarray:  # the pull-off force, model over measured: a row
        return np.array([1.5 * math.pi * w * radius / off]) if off else np.zeros(0)

    scale = max(float(np.abs(fn).max()), off or 0.0, 1e-300) / (math.pi * radius)
    fit = fit_profile(shape, extra, floor=floor, scale=scale, extra_rows=int(off is not None))
    cal = Calibration(
        tau=fit.tau,
        work=fit.work,
        tau_sigma=fit.tau_sigma,
        work_sigma=fit.work_sigma,
        covariance=fit.covariance,
        rows=int(fn.size + (off is not None)),
        residual_rms=fit.rms,
        radius=float(radius),
        e_star=float(e_star),
        work_floor=floor,
        pull_off=off,
        ranges=fit.ranges,
    )
    hertz = fit.tau_at(0.0) if floor == 0 and off is None else None
    refuse(cal, fn, ff, source, unit, hertz_tau=hertz)
    return cal
