"""Peak contact pressure of power-law asperities against closed forms and quadrature."""

import math

import numpy as np
import pytest
import torch
from scipy.integrate import quad
from scipy.special import hyp2f1

from metainterface.errors import MetainterfaceError
from metainterface.physics import CellSettings, Design, contact_radius, design_sweep, kappa
from metainterface.physics.limits import (
    asperity_peak_pressures,
    check_pressure,
    peak_factor,
    peak_location,
    peak_pressure,
    pressure_penalty,
    pressure_shape,
)

f64 = torch.float64


def _t(x):
    return torch.as_tensor(x, dtype=f64)


def _shape_by_quad(gamma: float, t: float) -> float:
    """int_t^1 s^(g-1) / sqrt(s^2 - t^2) ds, the endpoint singularity as a quad weight."""
    val, _ = quad(
        lambda s: s ** (gamma - 1) / math.sqrt(s + t), t, 1.0, weight="alg", wvar=(-0.5, 0.0)
    )
    return val


@pytest.mark.parametrize("radius", [1.0, 0.3])
def test_hertz_peak_is_the_centre_pressure(radius):
    e_star = 2.5
    delta = _t([1e-4, 0.003, 0.02]) * radius
    a = contact_radius(_t(2.0), delta, radius)
    p = peak_pressure(_t(2.0), delta, radius, e_star)
    torch.testing.assert_close(p, 2 * e_star * a / (math.pi * radius), rtol=1e-12, atol=0)
    assert float(peak_location(_t(2.0))) == 0.0


def test_gamma_4_peaks_off_centre_at_a_over_sqrt2():
    t = _t(np.linspace(0, 1, 11))
    expected = (1 + 2 * t**2) * torch.sqrt(1 - t**2) / 3
    torch.testing.assert_close(pressure_shape(_t(4.0), t), expected, rtol=1e-12, atol=1e-14)
    assert float(peak_location(_t(4.0))) == pytest.approx(1 / math.sqrt(2), abs=1e-6)
    assert float(peak_factor(_t(4.0))) == pytest.approx(math.sqrt(2) / 3, rel=1e-9)
    # p_max = E* gamma kappa c a^(gamma-1) I(t*) / pi with c = 1/2, R = 1
    delta = _t(0.02)
    a = contact_radius(_t(4.0), delta)
    kc = kappa(_t(4.0)) * 0.5
    closed = 4 * kc * a**3 * math.sqrt(2) / 3 / math.pi
    torch.testing.assert_close(peak_pressure(_t(4.0), delta), closed, rtol=1e-9, atol=0)


@pytest.mark.parametrize("gamma", [1.3, 1.8, 2.0, 2.6, 3.3, 5.0, 9.0])
def test_centre_value_and_quadrature(gamma):
    assert float(pressure_shape(_t(gamma), _t(0.0))) == pytest.approx(1 / (gamma - 1))
    for t in (1e-3, 0.1, 0.45, 0.8, 0.99):
        ref = _shape_by_quad(gamma, t)
        assert float(pressure_shape(_t(gamma), _t(t))) == pytest.approx(ref, rel=1e-8)


@pytest.mark.parametrize("gamma", [2.2, 2.9, 3.5, 6.0])
def test_peak_is_the_maximum_of_the_hypergeometric_profile(gamma):
    t = np.linspace(0.0, 1.0, 20001)[:-1]
    profile = np.sqrt(1 - t**2) * hyp2f1(1 - gamma / 2, 1, 1.5, 1 - t**2)
    assert float(peak_factor(_t(gamma))) == pytest.approx(profile.max(), rel=1e-6)
    assert float(peak_location(_t(gamma))) == pytest.approx(t[profile.argmax()], abs=2e-3)
    assert profile.max() > profile[0]  # above gamma = 2 the centre is not the peak


@pytest.mark.parametrize("gamma", [1.2, 1.6, 1.99])
def test_below_gamma_2_the_centre_is_the_peak(gamma):
    profile = [_shape_by_quad(gamma, x) for x in np.linspace(0.01, 0.99, 21)]
    assert max(profile) < 1 / (gamma - 1)
    assert float(peak_location(_t(gamma))) == 0.0


def test_peak_pressure_is_differentiable_and_zero_out_of_contact():
    gamma = _t([1.8, 2.0, 2.7, 4.0]).requires_grad_()
    delta = _t([0.01, 0.0, 0.015, -0.01]).requires_grad_()
    p = peak_pressure(gamma, delta)
    assert p[1] == 0 and p[3] == 0
    p.sum().backward()
    assert torch.isfinite(gamma.grad).all() and torch.isfinite(delta.grad).all()
    g = _t([1.9, 2.5, 3.7]).requires_grad_()
    d = _t([0.004, 0.01, 0.02]).requires_grad_()
    assert torch.autograd.gradcheck(lambda a, b: peak_pressure(a, b, 1.0, 1.0), (g, d))


def _design():
    settings = CellSettings(n_asperities=4)
    return Design(gamma=[1.8, 2.0, 3.0, 4.0], h=[0.001, 0.001, 0.005, 0.03], settings=settings)


def test_asperity_pressures_at_delta_max_and_the_report():
    design = _design()
    gamma, h = design.tensors()
    peaks = asperity_peak_pressures(gamma, h, design.settings)[0]
    local = design.settings.delta_max - (design.h - design.h.min())
    expected = peak_pressure(gamma[0], _t(local))
    torch.testing.assert_close(peaks, expected)
    assert peaks[3] == 0  # h beyond Delta_max: never touches
    limit = float(peaks[:3].min() + peaks[:3].max()) / 2
    report = check_pressure(design, limit)
    assert report.failing == [k for k in range(4) if peaks[k] > limit]
    assert not report.ok
    assert "would yield" in report.summary()
    in_pa = check_pressure(design, limit * 2e6, e_star=2e6)
    assert in_pa.failing == report.failing
    assert in_pa.to_dict()["limit_pa"] == pytest.approx(limit * 2e6)
    assert check_pressure(design, 1.0).ok
    with pytest.raises(MetainterfaceError, match="must be > 0"):
        check_pressure(design, 0.0)


def test_penalty_is_zero_below_the_limit_and_pushes_down_above():
    design = _design()
    gamma, h = design.tensors()
    gamma.requires_grad_()
    h.requires_grad_()
    peaks = asperity_peak_pressures(gamma, h, design.settings).detach()
    below = pressure_penalty(gamma, h, design.settings, float(peaks.max()) * 1.01)
    assert float(below.detach()[0]) == 0
    pen = pressure_penalty(gamma, h, design.settings, float(peaks.max()) * 0.5)
    assert pen.shape == (1,) and float(pen.detach()[0]) > 0
    pen.sum().backward()
    assert torch.isfinite(gamma.grad).all() and torch.isfinite(h.grad).all()
    assert h.grad.abs().sum() > 0


@pytest.mark.slow
@pytest.mark.parametrize("gamma", [2.0, 3.0])
def test_peak_matches_bem_off_centre(gamma):
    """A single asperity in its cell: BEM peak pressure and its radius match the closed form."""
    pytest.importorskip("tamaas")
    from metainterface.validation.bem import solve_path
    from metainterface.validation.heightmap import height_map

    settings = CellSettings(n_asperities=1)
    design = Design(gamma=[gamma], h=[0.0], settings=settings)
    gamma_t, _ = design.tensors()
    p_star = float(design_sweep(design).p_star[0, -1])
    cell = height_map(design, 384)
    path = solve_path(cell.heights, cell.cell_side, np.array([p_star]), cell.owner, 1)
    peak = check_pressure(design, 1.0).peak[0]
    assert path.p_max[0] == pytest.approx(peak, rel=0.02)
    i, j = np.unravel_index(path.pressure.argmax(), path.pressure.shape)
    r = np.hypot(i - 192, j - 192) * cell.spacing
    a = math.sqrt(path.alpha[0] * cell.cell_side**2 / math.pi)
    assert r / a == pytest.approx(float(peak_location(gamma_t[0])[0]), abs=0.03)
