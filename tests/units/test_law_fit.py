"""Measured friction data -> a monotone smooth law (physical/_lawfit.py)."""

import numpy as np
import pytest

from metainterface.errors import MetainterfaceError
from metainterface.units._lawfit import fit_law
from metainterface.units.friction import FrictionLaw, friction_target, prepare_law

TAU, E_STAR, RADIUS, AREA = 0.25e6, 2e6, 0.5e-3, 4e-4


def saturating(fn):
    return 3.0 * (1.0 - np.exp(-fn / 2.5))  # N, 0 to about 2.9 N over 0-8 N


def _noisy(k, noise, seed=0):
    rng = np.random.default_rng(seed)
    fn = rng.uniform(0.2, 8.0, k)  # unsorted
    return fn, saturating(fn) + noise * rng.standard_normal(k)


@pytest.mark.parametrize(("k", "noise", "tol"), [(40, 0.03, 0.03), (8, 0.03, 0.06), (5, 0.0, 0.03)])
def test_fit_recovers_a_known_law_from_noisy_unsorted_samples(k, noise, tol):
    # tolerance: the largest error over the loads measured, relative to the largest
    # friction (~3 N); with 1 % noise a few times noise / sqrt(points per knot)
    fn, ff = _noisy(k, noise)
    fit = fit_law(fn, ff)
    grid = np.linspace(0.0, fn.max(), 200)  # the fit covers the loads measured
    assert np.abs(fit(grid) - saturating(grid)).max() < tol * 3.0
    assert fit(np.array([0.0]))[0] == pytest.approx(0.0, abs=1e-12)
    assert np.all(np.diff(fit(grid)) >= -1e-12)  # monotone


def test_fit_is_monotone_through_falling_scatter_and_repeated_loads():
    fn = np.array([1.0, 1.0, 1.0, 2.0, 2.0, 3.0, 3.0, 4.0, 4.0, 5.0])
    ff = np.array([0.5, 0.6, 0.4, 0.9, 0.7, 0.8, 1.2, 1.1, 1.0, 1.3])  # falls between rows
    fit = fit_law(fn, ff)
    grid = np.linspace(0.0, 5.0, 100)
    assert np.all(np.diff(fit(grid)) >= -1e-12)
    assert fit.residual_rms > 0  # scatter is not interpolated
    assert "monotone cubic spline" in fit.summary()


def test_auto_fits_measured_rows_and_keeps_a_clean_law():
    fn, ff = _noisy(30, 0.05, seed=1)
    law = FrictionLaw(fn, ff, rows=np.arange(1, fn.size + 1), source="bench")
    fitted, fit = prepare_law(law, "auto")
    assert fit is not None and fitted.normal_force[0] == 0.0
    assert np.all(np.diff(fitted.normal_force) > 0)
    assert np.all(np.diff(fitted.friction_force) >= 0)
    clean_fn = np.linspace(0.5, 8.0, 20)
    clean = FrictionLaw(clean_fn, saturating(clean_fn), rows=np.arange(1, 21), source="clean")
    kept, none = prepare_law(clean, "auto")
    assert none is None and kept is clean
    with pytest.raises(MetainterfaceError, match=r"cannot decrease|not above"):
        prepare_law(law, "never")
    with pytest.raises(MetainterfaceError, match="fit must be one of"):
        prepare_law(law, "sometimes")


def test_friction_target_records_the_fit():
    fn, ff = _noisy(7, 0.02, seed=2)
    law = FrictionLaw(fn, ff, rows=np.arange(1, 8), source="few")
    t = friction_target(law, shear_strength=TAU, e_star=E_STAR, radius=RADIUS, area=AREA)
    assert t.fit is not None
    rec = t.record()["fit"]
    assert rec["raw_normal_force_n"] == [float(v) for v in fn]
    assert rec["residual_rms_n"] == pytest.approx(t.fit.residual_rms)
    assert np.all(np.diff(t.p_star) > 0) and t.p_star[0] == 0


def test_too_few_distinct_loads_to_fit():
    law = FrictionLaw(np.array([1.0, 1.0, 2.0]), np.array([0.1, 0.2, 0.3]), np.arange(1, 4))
    with pytest.raises(MetainterfaceError, match="at least 3 distinct positive normal forces"):
        prepare_law(law, "always")
