"""The error measure: alpha exactly at the target's pressures, against closed forms."""

import math

import numpy as np
import pytest
import torch

from metainterface.inverse import TargetGrid, builtin_target, relative_error
from metainterface.physics import CellSettings
from metainterface.physics.registry import get_model

S = CellSettings()


@pytest.mark.parametrize("name", ["saturating", "bilinear"])
def test_a_targets_own_design_scores_zero(name):
    # the built-in design targets are sampled exactly: only round-off is left (~1e-16)
    t = builtin_target(name)
    grid = TargetGrid.from_curves([(t.p_star, t.alpha)], 128)
    g = torch.tensor([t.meta["gamma"]], dtype=torch.float64)
    h = torch.tensor([t.meta["h"]], dtype=torch.float64)
    assert float(relative_error(g, h, S, grid)[0]) < 1e-12


@pytest.mark.parametrize("physics", ["independent", "interacting"])
def test_single_hertz_asperity_at_given_pressures_matches_the_closed_form(physics):
    # one gamma = 2 asperity in a 1 x 1 lattice, E* = 1: F = 4/3 a^3 / R, so a^3 = 3 F R / 4
    # and alpha = pi a^2 / A with F = P* A. The lattice's own image field shifts the tip
    # uniformly in the interacting model, so only the independent one is Hertz exactly.
    s = CellSettings(n_asperities=1)
    g = torch.tensor([[2.0]], dtype=torch.float64)
    h = torch.zeros((1, 1), dtype=torch.float64)
    a_nom = s.nominal_area
    p_max = 4.0 / 3.0 * s.delta_max**1.5 / a_nom  # Hertz at Delta_max: a = sqrt(R Delta)
    p = torch.linspace(0.0, 0.999, 50, dtype=torch.float64)[None] * p_max
    alpha, _ = get_model(physics).alpha_at(g, h, s, p, exact=True)
    closed = math.pi * (3.0 * p * a_nom / 4.0) ** (2.0 / 3.0) / a_nom
    if physics == "independent":
        np.testing.assert_allclose(alpha, closed, rtol=1e-10, atol=1e-15)
        interpolated, _ = get_model().alpha_at(g, h, s, p)
        assert float((interpolated - closed).abs().max()) > 1e3 * float(
            (alpha - closed).abs().max()
        )
    else:  # a few % off Hertz at most, and still the model's own interpolated curve
        fine, _ = get_model(physics).alpha_at(g, h, s, p, n_delta=20001)
        np.testing.assert_allclose(alpha, fine, rtol=1e-6, atol=1e-12)


def _random_designs(b: int) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
    gen = torch.Generator().manual_seed(3)
    g = 1.8 + 2.2 * torch.rand((b, 9), generator=gen, dtype=torch.float64)
    h = S.delta_max * torch.rand((b, 9), generator=gen, dtype=torch.float64)
    p_max = get_model().alpha_at(g, h, S, torch.zeros((b, 1), dtype=torch.float64))[1]
    p = torch.linspace(0.0, 1.1, 40, dtype=torch.float64)[None] * p_max[:, None]
    return g, h, p


def test_exact_alpha_is_the_limit_of_finer_sweeps_and_is_held_beyond_p_max():
    g, h, p = _random_designs(4)
    exact, p_max = get_model().alpha_at(g, h, S, p, exact=True)
    fine, _ = get_model().alpha_at(g, h, S, p, n_delta=40001)
    coarse, _ = get_model().alpha_at(g, h, S, p)
    assert float((fine - exact).abs().max()) < 1e-4 * float((coarse - exact).abs().max())
    beyond = p >= p_max[:, None]
    assert bool(beyond.any())
    last = get_model().alpha_at(g, h, S, p_max[:, None], exact=True)[0]
    torch.testing.assert_close(exact, torch.where(beyond, last, exact))


def test_exact_alpha_gradient_matches_finite_differences():
    # the implicit-function gradient d alpha/d theta = da/dtheta - (1/S*) dP*/dtheta
    g, h, p = _random_designs(2)
    p = p[:, 1:-6]  # inside (0, P*_max)
    g.requires_grad_(True)
    h.requires_grad_(True)
    assert torch.autograd.gradcheck(
        lambda gg, hh: get_model().alpha_at(gg, hh, S, p, exact=True)[0],
        (g, h),
        eps=1e-7,
        atol=1e-6,
        rtol=1e-4,
    )


def test_exact_alpha_rejects_the_softplus():
    g, h, p = _random_designs(1)
    with pytest.raises(ValueError, match="exact contact law"):
        get_model().alpha_at(g, h, S, p, exact=True, smooth=1e4)
