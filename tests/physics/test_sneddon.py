"""Single asperity against closed forms: Hertz, the cone, Table 1 (gamma = 3), quadrature."""

import itertools
import math

import numpy as np
import pytest
import torch
from scipy import integrate
from scipy.special import gamma as gamma_fn

from metainterface.physics import area, contact_radius, force, indentation, kappa

F64 = torch.float64


def t(x):
    return torch.as_tensor(x, dtype=F64)


@pytest.mark.parametrize("radius", [1.0, 0.3, 5.0])
def test_hertz(radius):
    delta = t(np.linspace(1e-4, 0.05, 30))
    g = torch.full_like(delta, 2.0)
    np.testing.assert_allclose(
        contact_radius(g, delta, radius), np.sqrt(radius * delta), rtol=1e-12
    )
    expected_f = 4 / 3 * 2.5 * math.sqrt(radius) * delta**1.5  # E* = 2.5
    np.testing.assert_allclose(force(g, delta, radius, e_star=2.5), expected_f, rtol=1e-12)


def test_kappa_table_values():
    np.testing.assert_allclose(kappa(t([1.0, 2.0, 3.0])), [math.pi / 2, 2.0, 3 * math.pi / 4])


def _force_of_area(gamma: float, a_real, radius: float, e_star: float):
    """F(A) evaluated by the model: invert A -> delta through the contact radius."""
    a = np.sqrt(np.asarray(a_real) / math.pi)
    kc = float(kappa(t(gamma))) / (2 * radius ** (gamma - 1))
    delta = t(kc * a**gamma)
    return force(torch.full_like(delta, gamma), delta, radius, e_star), area(
        torch.full_like(delta, gamma), delta, radius
    )


@pytest.mark.parametrize(
    ("gamma", "closed_form"),
    [
        (1.0, lambda a, r, e: e * a / 4),  # cone: F = E* A / 4
        (2.0, lambda a, r, e: 4 * e / (3 * r * math.pi**1.5) * a**1.5),
        (3.0, lambda a, r, e: 9 * e / (16 * math.pi * r**2) * a**2),
    ],
)
def test_table1_force_of_area(gamma, closed_form):
    radius, e_star = 0.7, 3.0
    a_real = np.linspace(1e-4, 0.2, 25)
    f, a_model = _force_of_area(gamma, a_real, radius, e_star)
    np.testing.assert_allclose(a_model, a_real, rtol=1e-12)
    np.testing.assert_allclose(f, closed_form(a_real, radius, e_star), rtol=1e-10)


@pytest.mark.parametrize("gamma", [1.5, 1.8, 2.5, 3.3, 4.0])
def test_sneddon_integrals_by_quadrature(gamma):
    """Sneddon: delta = a int_0^1 f'(x a) / sqrt(1 - x^2) dx, F = 2 E* int_0^a r (delta - f(r))
    / sqrt(a^2 - r^2) dr, for f = c r^gamma with c = 1/(2 R^(gamma-1))."""
    radius, e_star = 1.3, 1.0
    c = 0.5 * radius ** (1 - gamma)
    for a in (0.05, 0.2, 0.4):
        # r = a sin(theta) removes the 1/sqrt endpoint singularities of both integrals
        delta, _ = integrate.quad(
            lambda th, a=a: c * gamma * (a * math.sin(th)) ** (gamma - 1), 0, math.pi / 2
        )
        delta *= a
        f_quad, _ = integrate.quad(
            lambda th, a=a, d=delta: a * math.sin(th) * (d - c * (a * math.sin(th)) ** gamma),
            0,
            math.pi / 2,
        )
        f_quad *= 2 * e_star
        g = t([gamma])
        np.testing.assert_allclose(contact_radius(g, t([delta]), radius), [a], rtol=1e-7)
        np.testing.assert_allclose(force(g, t([delta]), radius, e_star), [f_quad], rtol=1e-7)
    # kappa against its gamma-function definition
    expected = math.sqrt(math.pi) * gamma_fn(gamma / 2 + 1) / gamma_fn((gamma + 1) / 2)
    assert float(kappa(t(gamma))) == pytest.approx(expected, rel=1e-12)


def test_softplus_converges_to_macaulay():
    x = t(np.linspace(-0.01, 0.01, 401))
    exact = indentation(x)
    errs = [float((indentation(x, smooth=k) - exact).abs().max()) for k in (1e3, 1e4, 1e5, 1e6)]
    assert all(b < a for a, b in itertools.pairwise(errs))
    assert errs[0] == pytest.approx(math.log(2) / 1e3, rel=1e-6)  # worst at x = 0
    assert errs[-1] < 1e-6


def test_zero_indentation_is_zero_with_finite_gradients():
    g = t([1.8, 2.0, 4.0]).requires_grad_()
    d = t([0.0, 0.0, 0.0]).requires_grad_()
    (force(g, d) + area(g, d)).sum().backward()
    assert torch.isfinite(g.grad).all() and torch.isfinite(d.grad).all()
    assert float(area(g, d).detach().sum()) == 0.0
