"""mi.tolerance and mi.min_radius as a user calls them, against closed forms."""

import math

import numpy as np
import pytest
from scipy.special import gammaln

import metainterface as mi

DMAX = 0.02


def kc(g):
    """kappa(gamma) c with c = 1 / 2 (R = 1): the Sneddon indentation-radius constant."""
    return 0.5 * np.sqrt(np.pi) * np.exp(gammaln(g / 2 + 1) - gammaln((g + 1) / 2))


def single_alpha(g, p_star, side):
    """alpha of one asperity (shape g, R = 1) at P*, cell side L, in closed form:
    F = 2g/(g+1) delta a, a = (delta / kc)^(1/g), A = pi a^2, P* = F / L^2."""
    force = p_star * side**2
    a = (force * (g + 1) / (2 * g) / kc(g)) ** (1 / (g + 1))
    return np.pi * a**2 / side**2


def test_single_asperity_height_error_changes_nothing_and_shape_error_is_closed_form():
    d = mi.Design(gamma=[2.7], h=[0.0], settings=mi.CellSettings(n_asperities=1))
    side = d.settings.cell_side
    r = mi.tolerance(d, sigma_h=0.2 * DMAX, samples=256, seed=3)
    # a lone asperity's height error only shifts its engagement: alpha(P*) is unchanged
    assert r.error_p95 < 1e-9 and np.allclose(r.alpha_p95, r.alpha_nominal, atol=1e-12)
    np.testing.assert_allclose(r.alpha_nominal[1:], single_alpha(2.7, r.p_star[1:], side), 1e-8)
    r = mi.tolerance(d, sigma_gamma=0.1, samples=512, seed=3)
    expect = single_alpha(r.gamma[:, :1], r.p_star[None, 1:], side)
    np.testing.assert_allclose(r.alpha[:, 1:], expect, rtol=1e-7)
    np.testing.assert_allclose(r.alpha_p95[1:], np.quantile(expect, 0.95, axis=0), rtol=1e-7)
    assert abs(np.std(r.gamma[:, 0]) - 0.1) < 0.01


def sneddon_curve(gamma, h, settings, delta):
    """P* and alpha of independent asperities along delta, each shifted by its offset."""
    x = np.clip(delta[:, None] - (h - h.min())[None, :], 0.0, None)
    a = (x / kc(gamma)) ** (1 / gamma)
    force = (2 * gamma / (gamma + 1) * x * a).sum(1)
    area = (np.pi * a**2).sum(1)
    return force / settings.nominal_area, area / settings.nominal_area


def test_height_errors_shift_each_asperity_engagement():
    d = mi.Design(gamma=[2.0, 3.0, 2.5, 3.5], h=[0.0, 0.004, 0.01, 0.013])
    r = mi.tolerance(d, sigma_h=0.05 * DMAX, samples=512, seed=1, target="nominal")
    delta = np.linspace(0, 2 * DMAX, 200001)
    for i in (0, 7, 33):
        np.testing.assert_array_equal(r.gamma[i], d.gamma)  # shapes untouched
        p, alpha = sneddon_curve(d.gamma, r.h[i], d.settings, delta)
        np.testing.assert_allclose(r.alpha[i], np.interp(r.p_star, p, alpha), atol=2e-6)
    # the made heights are the design's plus independent errors of the asked size
    e = r.h - d.h
    assert abs(e.std() / (0.05 * DMAX) - 1) < 0.1
    corr = np.corrcoef(e.T) - np.eye(4)
    assert np.abs(corr).max() < 0.15


def test_monte_carlo_converges_to_first_order_as_sigma_goes_to_zero():
    d = mi.Design(gamma=[2.2, 3.1, 2.6, 3.8], h=[0.0, 0.005, 0.009, 0.012])
    gaps = []
    for scale in (0.1, 0.01, 0.001):
        r = mi.tolerance(
            d,
            sigma_h=scale * DMAX,
            sigma_gamma=scale,
            scale_sigma=scale,
            samples=2048,
            seed=0,
            target="nominal",
        )
        gaps.append(abs(r.error_p95 / r.error_p95_linear - 1))
        if scale == 0.001:
            assert r.error_p95 < 0.01
            inner = slice(10, None)
            half = (r.alpha_p95 - r.alpha_p05)[inner] / 2
            np.testing.assert_allclose(half, 1.6449 * r.alpha_sd_linear[inner], rtol=0.1)
            assert abs(r.error_median / r.error_median_linear - 1) < 0.05
    assert gaps[-1] < 0.05 and gaps[-1] < gaps[0]


def test_errors_are_to_the_design_files_target_and_match_design(tmp_path):
    t = mi.Target.builtin("saturating")
    res = mi.design(
        t,
        method="multistart",
        out=tmp_path / "d",
        verify=False,
        effort=mi.Effort(starts=4, hedge=0, fallback=0, refine_settings=None),
    )
    r = mi.tolerance(tmp_path / "d" / "design.json", sigma_h=0.0, samples=16)
    assert r.reference is not None and r.reference.name == "saturating"
    assert r.error_nominal == pytest.approx(res.error, rel=1e-3, abs=1e-7)
    assert np.allclose(r.errors, r.error_nominal, rtol=1e-9)  # no error, every sample nominal


def test_a_design_result_is_measured_to_its_own_target():
    res = mi.design("saturating", method="multistart", verify=False, effort=mi.Effort(starts=4))
    r = mi.tolerance(res, sigma_h=0.0, samples=16)
    assert r.reference is not None and r.reference.name == "saturating"
    assert r.error_nominal == pytest.approx(res.error, rel=1e-3, abs=1e-7)
    # its bare Design carries no target: the errors are to its own curve
    assert mi.tolerance(res.design, sigma_h=0.0, samples=16).error_nominal < 1e-12
    # an explicit target still wins
    other = mi.tolerance(res, sigma_h=0.0, samples=16, target="linear")
    assert other.reference.name == "linear" and other.error_nominal > 10 * res.error
    s = mi.min_radius(res, printer_sigma="1um", max_error="20%", samples=64)
    assert "target saturating" in s.settings["reference"]


def test_nominal_error_of_a_design_that_stops_short_is_charged_its_coverage():
    # one asperity reaches P*_max at Delta_max; a target running on to 1.5 P*_max is met
    # exactly below it: the fit there is ~0, the third of the load range it misses is
    # charged in full, error = sqrt(0 + (1 - 1/1.5)^2) = 1/3, as design measures it
    d = mi.Design(gamma=[2.7], h=[0.0], settings=mi.CellSettings(n_asperities=1))
    side = d.settings.cell_side
    p_max = float(mi.curve(d).p_star.max())
    p = np.linspace(0.0, 1.5 * p_max, 2001)[1:]
    exact = single_alpha(2.7, p, side)
    target = mi.Target(p_star=p, alpha=exact, name="beyond")
    r = mi.tolerance(d, sigma_h=0.0, samples=16, target=target)
    assert r.error_nominal == pytest.approx(1 / 3, rel=1e-3)
    assert r.coverage == pytest.approx(1 / 1.5, rel=1e-6) and r.carrying == 1
    # made cells are loaded past Delta_max: the same curve, all the range covered
    assert np.all(r.errors < 1e-3)
    assert "coverage 66.7 %" in repr(r)


def test_units_need_a_radius_and_scale_by_it():
    d = mi.Design(gamma=[2.0, 3.0, 2.5, 3.5], h=[0.0, 0.004, 0.01, 0.013])
    a = mi.tolerance(d, sigma_h="1um", radius="0.5mm", samples=64)
    b = mi.tolerance(d, sigma_h=0.002, samples=64)
    np.testing.assert_array_equal(a.band()["alpha_p95"], b.band()["alpha_p95"])
    assert a.settings.sigma_h == pytest.approx(0.002)
    assert "1 um" in repr(a) and "p95" in repr(a)


@pytest.mark.parametrize(
    ("kwargs", "fragment"),
    [
        ({"sigma_h": -0.001}, "sigma_h"),
        ({"sigma_h": float("nan")}, "sigma_h"),
        ({"sigma_h": "-1um", "radius": "1mm"}, "sigma_h must be >= 0"),
        ({"sigma_h": "1um"}, "give radius"),
        ({"sigma_h": "1MPa", "radius": "1mm"}, "sigma_h expects a length"),
        ({"sigma_gamma": -0.1}, "sigma_gamma"),
        ({"sigma_gamma": math.inf}, "sigma_gamma"),
        ({"scale_sigma": 0.9}, "scale_sigma"),
        ({"samples": 0}, "samples"),
        ({"samples": 10**9}, "samples"),
        ({"seed": -1}, "seed"),
        ({"radius": "2s", "sigma_h": "1um"}, "radius expects a length"),
        ({"model": "nope"}, "model must be one of"),
    ],
)
def test_bad_input_is_one_line(kwargs, fragment):
    d = mi.Design(gamma=[2.0, 3.0, 2.5, 3.5], h=[0.0, 0.004, 0.01, 0.013])
    with pytest.raises(mi.MetainterfaceError) as exc:
        mi.tolerance(d, **{"samples": 16, **kwargs})
    assert fragment in str(exc.value) and "\n" not in str(exc.value)


def test_min_radius_is_where_the_p95_meets_the_budget():
    d = mi.Design(gamma=[2.0, 3.0, 2.5, 3.5], h=[0.0, 0.004, 0.01, 0.013])
    s = mi.min_radius(d, printer_sigma="1um", max_error="5%", samples=256, target="nominal")
    assert s.feasible and s.error_p95 <= 0.05
    assert "mm" in repr(s)
    r_mm = s.radius_m * 1e3
    at = mi.tolerance(d, sigma_h="1um", radius=f"{r_mm}mm", samples=256, target="nominal")
    assert at.error_p95 == pytest.approx(0.05, rel=0.01)
    below = mi.tolerance(d, sigma_h="1um", radius=f"{0.8 * r_mm}mm", samples=256, target="nominal")
    assert below.error_p95 > 0.05
    # a budget that the shape errors alone break: no radius helps
    s = mi.min_radius(
        d, printer_sigma="1um", max_error=0.001, sigma_gamma=0.3, samples=64, target="nominal"
    )
    assert not s.feasible and "no radius" in repr(s)
    with pytest.raises(mi.MetainterfaceError, match="max_error"):
        mi.min_radius(d, printer_sigma="1um", max_error="five")
    with pytest.raises(mi.MetainterfaceError, match="printer_sigma"):
        mi.min_radius(d, printer_sigma="1kg", max_error=0.05)


def test_scale_error_scales_every_height_of_a_sample_alike():
    d = mi.Design(gamma=[2.0, 3.0, 2.5, 3.5], h=[0.0, 0.004, 0.01, 0.013])
    r = mi.tolerance(d, scale_sigma=0.05, samples=256, seed=2, target="nominal")
    ratio = r.h[:, 1:] / d.h[1:]
    np.testing.assert_allclose(ratio, ratio[:, :1].repeat(3, 1), rtol=1e-12)
    assert abs(ratio[:, 0].std() - 0.05) < 0.01 and r.error_p95 > 0


def test_radius_defaults_to_the_design_files_physical_block(tmp_path):
    d = mi.Design(gamma=[2.0, 3.0, 2.5, 3.5], h=[0.0, 0.004, 0.01, 0.013])
    path = d.save(tmp_path / "d.json", physical={"radius_m": 5e-4})
    r = mi.tolerance(path, sigma_h="1um", samples=16)
    assert r.settings.radius_m == 5e-4 and r.settings.sigma_h == pytest.approx(0.002)
