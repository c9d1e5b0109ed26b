"""A monotone smooth curve through measured friction data.

Measured laws come with scatter, repeated normal forces, unsorted rows and few points; the
design needs a friction force that starts at 0 and never decreases (F_f = tau A_real). The
fit is a cubic B-spline on [0, max F_n] with a clamped knot vector, written as

    F_f(F_n) = sum_j c_j B_j(F_n),   c_0 = 0,   c_j = c_{j-1} + d_j,   d_j >= 0.

A spline whose coefficients never decrease never decreases itself (its derivative is a
positive combination of the coefficient differences, de Boor, *A Practical Guide to
Splines*, ch. X), and c_0 = 0 pins F_f(0) = 0: so every fit is a valid law, and the
non-negative least squares in d (``scipy.optimize.lsq_linear``) is convex, with one answer
for any data. Why a spline and not a parametric law: the user's law can be saturating,
bilinear or anything monotone; the spline assumes only smoothness. The number of interior
knots (uniform in F_n) is chosen by generalised cross-validation, GCV = K RSS / (K - p)^2
(Craven and Wahba 1979) with p the free coefficients (those not held at the bound), so
noisy data get few knots and clean dense data more.

With adhesion (``offset=True``) friction need not vanish with the load: c_0 >= 0 is then a
free coefficient too (B-splines sum to 1, so it is a constant added to the law), still a
convex non-negative least squares, and the fit keeps the offset F_f(0) = c_0.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

#: Interior knots tried by GCV (0 = a single cubic piece).
MAX_INTERIOR_KNOTS = 8
#: Points the fitted law is sampled at for the design target.
FIT_POINTS = 64


@dataclass(frozen=True)
class LawFit:
    """A monotone cubic spline fitted to friction data.

    knots: the clamped knot vector [N]; coef: (n_basis,) B-spline coefficients [N], non-
    decreasing from 0. raw_normal, raw_friction: (K,) the data as given [N]. residual_rms:
    root mean square of data - fit [N]. interior_knots: the number GCV chose.
    """

    knots: np.ndarray
    coef: np.ndarray
    raw_normal: np.ndarray
    raw_friction: np.ndarray
    residual_rms: float
    interior_knots: int
    offset: bool = False

    def __call__(self, normal_force: np.ndarray) -> np.ndarray:
        """The fitted friction force [N] at loads (M,) [N] in [0, max F_n]."""
        return _basis(np.asarray(normal_force, dtype=np.float64), self.knots) @ self.coef

    @property
    def relative_residual(self) -> float:
        """residual_rms over the largest fitted friction force."""
        top = float(self(np.array([self.raw_normal.max()]))[0])
        return self.residual_rms / top if top > 0 else float("inf")

    def sample(self, points: int = FIT_POINTS) -> tuple[np.ndarray, np.ndarray]:
        """(F_n, F_f) (points,) [N]: the fit on uniform loads over [0, max F_n]."""
        fn = np.linspace(0.0, float(self.raw_normal.max()), points)
        ff = np.maximum.accumulate(np.maximum(self(fn), 0.0))  # exact monotone to round-off
        if not self.offset:
            ff[0] = 0.0
        return fn, ff

    def summary(self) -> str:
        """One line: what was fitted and how far the data scatter around it."""
        return (
            f"fitted a monotone cubic spline ({self.interior_knots} interior knots, by GCV) "
            f"to {self.raw_normal.size} rows: rms residual {self.residual_rms:.3g} N "
            f"({100 * self.relative_residual:.2g} % of the largest friction force)"
        )


def _knots(top: float, interior: int) -> np.ndarray:
    inner = np.linspace(0.0, top, interior + 2)
    return np.concatenate([[0.0] * 3, inner, [top] * 3])


def _basis(x: np.ndarray, knots: np.ndarray) -> np.ndarray:
    """(M, n_basis) cubic B-spline basis at x (clamped knots; the right end included)."""
    from scipy.interpolate import BSpline

    x = np.clip(x, knots[0], knots[-1])
    return BSpline.design_matrix(x, knots, 3, extrapolate=False).toarray()


def _fit(
    x: np.ndarray, y: np.ndarray, interior: int, offset: bool = False
) -> tuple[np.ndarray, np.ndarray, int]:
    """(knots, coef, free coefficients) of the monotone fit with ``interior`` knots; with
    ``offset`` c_0 >= 0 is free (a constant added), else c_0 = 0."""
    from scipy.optimize import lsq_linear

    knots = _knots(float(x.max()), interior)
    b = _basis(x, knots)
    # c = L d with c_0 = 0: column j of B L is the sum of B's columns j..end
    cum = np.cumsum(b[:, ::-1], axis=1)[:, ::-1][:, 1:]
    if offset:  # the constant c_0: the sum of all basis columns, 1 on [0, max F_n]
        cum = np.concatenate([b.sum(axis=1, keepdims=True), cum], axis=1)
    scale = max(float(np.abs(y).max()), 1e-300)
    sol = lsq_linear(cum, y / scale, bounds=(0.0, np.inf), method="bvls")
    d = sol.x * scale
    c0 = 0.0
    if offset:
        c0, d = float(d[0]), d[1:]
    coef = c0 + np.concatenate([[0.0], np.cumsum(d)])
    free = int(np.count_nonzero(d > 1e-10 * scale)) + int(offset and c0 > 1e-10 * scale)
    return knots, coef, free


def fit_law(
    normal_force: np.ndarray, friction_force: np.ndarray, *, offset: bool = False
) -> LawFit:
    """The monotone spline through (F_n, F_f) data (K,) [N]: any order, repeats allowed;
    with ``offset`` (adhesion) F_f(0) >= 0 is fitted too, else pinned at 0.

    Needs at least 3 rows with a positive load; loads >= 0 and finite (checked by the caller).
    """
    x = np.asarray(normal_force, dtype=np.float64)
    y = np.asarray(friction_force, dtype=np.float64)
    k = x.size
    distinct = np.unique(x).size
    best = None
    for interior in range(MAX_INTERIOR_KNOTS + 1):
        # at most one coefficient per two distinct loads: GCV alone lets a few noisy
        # points pull in knots that follow the noise
        if 2 * (interior + 3) > distinct:
            break
        knots, coef, free = _fit(x, y, interior, offset)
        rss = float(np.sum((_basis(x, knots) @ coef - y) ** 2))
        gcv = k * rss / max(k - free, 1) ** 2
        if best is None or gcv < best[0] * (1 - 1e-9):
            best = (gcv, interior, knots, coef, rss)
    if best is None:  # fewer than 6 distinct loads: one cubic piece anyway
        knots, coef, _ = _fit(x, y, 0, offset)
        best = (0.0, 0, knots, coef, float(np.sum((_basis(x, knots) @ coef - y) ** 2)))
    _, interior, knots, coef, rss = best
    return LawFit(
        knots=knots,
        coef=coef,
        raw_normal=x,
        raw_friction=y,
        residual_rms=float(np.sqrt(rss / k)),
        interior_knots=interior,
        offset=offset,
    )
