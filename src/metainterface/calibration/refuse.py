"""A friction test the calibration's model cannot explain is refused, not fitted (issue 52).

A fit always returns numbers; these are the tests where they would mean nothing, each a
one-line error (exit 2 at the command line, nothing written):

- friction that falls as the load grows (rank correlation of the rows <= 0): with
  F_f = tau A_real and a contact that grows with the load (JKR sphere, or a design's cell
  under a rising force) friction never falls, so the columns or the test are wrong;
- residuals far above a friction test's noise: an rms relative residual above
  ``RESIDUAL_LIMIT`` (three times 5 %, the largest scatter of the tests the calibration's
  coverage benchmark draws, 1-5 %);
- a 95 % range that reaches tau <= 0 or w < 0: the test does not determine that value.
  A best fit exactly at w = 0 (the Hertz contact: no adhesion read) is kept, an answer.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from metainterface.errors import MetainterfaceError

#: The largest rms relative residual of a fit that is kept: 3 x 5 % (the noisiest test the
#: coverage benchmark draws); a test scattering more is not a JKR contact as modelled.
RESIDUAL_LIMIT = 0.15


def rank_correlation(x: np.ndarray, y: np.ndarray) -> float:
    """Spearman's rank correlation of two (K,) arrays (ties averaged)."""
    from scipy.stats import rankdata

    rx, ry = rankdata(x), rankdata(y)
    rx, ry = rx - rx.mean(), ry - ry.mean()
    den = math.sqrt(float((rx * rx).sum() * (ry * ry).sum()))
    return float((rx * ry).sum() / den) if den > 0 else 0.0


def refuse(
    cal: Any,
    fn: np.ndarray,
    ff: np.ndarray,
    source: str,
    unit: tuple[str, float] = ("N", 1.0),
    *,
    hertz_tau: float | None = None,
) -> None:
    """Raise a one-line MetainterfaceError where ``cal`` (a Calibration of the rows fn, ff
    (K,) [N]) is not an answer. unit: (label, N per unit) of the file's forces, for the
    message; hertz_tau: tau [Pa] of the fit at w = 0, offered where w is undetermined."""
    from metainterface.units.law_file import in_unit

    rho = rank_correlation(fn, ff)
    if rho <= 0:
        order = np.argsort(fn)
        lo, hi = order[0], order[-1]
        raise MetainterfaceError(
            f"{source}: friction falls as the load grows (rank correlation {rho:.2g} over "
            f"{fn.size} rows; {in_unit(ff[lo], unit)} at {in_unit(fn[lo], unit)}, "
            f"{in_unit(ff[hi], unit)} at {in_unit(fn[hi], unit)}): with F_f = tau A_real "
            "the contact grows with the load; check the columns and the test"
        )
    if not cal.residual_rms <= RESIDUAL_LIMIT:
        raise MetainterfaceError(
            f"{source}: the fit misses the test by {100 * cal.residual_rms:.3g} % rms, above "
            f"the {100 * RESIDUAL_LIMIT:.3g} % a friction test's scatter explains: the test is "
            f"not the contact modelled ({cal.contact}); nothing calibrated"
        )
    ci = cal.interval(0.95, floored=False)
    if not ci["tau"][0] > 0:
        raise MetainterfaceError(
            f"{source}: tau's 95 % range {ci['tau'][0] / 1e3:.3g} to {ci['tau'][1] / 1e3:.3g} "
            "kPa reaches tau <= 0: the test does not determine the shear strength"
        )
    if cal.work > 0 and not ci["work"][0] >= 0:
        hint = (
            f"; read without adhesion (w = 0) tau = {hertz_tau / 1e3:.4g} kPa"
            if hertz_tau is not None and math.isfinite(hertz_tau)
            else ""
        )
        raise MetainterfaceError(
            f"{source}: w's 95 % range (up to {ci['work'][1] * 1e3:.3g} mJ/m^2) reaches "
            "w < 0: the test does not determine the "
            f"work of adhesion (pull rows or the pull-off force pin it){hint}"
        )
