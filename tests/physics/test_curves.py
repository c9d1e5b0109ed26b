"""Unit-cell curves: lattice geometry, superposition, stiffness, gradients, gridding."""

import math

import numpy as np
import pytest
import torch

from metainterface.errors import MetainterfaceError
from metainterface.physics import CellSettings, curve, interp, kappa, sweep
from metainterface.physics.metrics import window_mean

F64 = torch.float64
S = CellSettings()


def random_designs(b, n=9, seed=0, dtype=F64, settings=S):
    gen = torch.Generator().manual_seed(seed)
    g = settings.gamma_min + (settings.gamma_max - settings.gamma_min) * torch.rand(
        b, n, generator=gen, dtype=dtype
    )
    h = settings.delta_max * torch.rand(b, n, generator=gen, dtype=dtype)
    return g, h


def test_a_max_and_cell_side():
    # a = (Delta_max / (kappa c))^(1/gamma) is largest at gamma_max = 4 for the defaults
    a4 = (0.02 / (8 / 3 * 0.5)) ** 0.25
    assert S.a_max == pytest.approx(a4, rel=1e-12)
    assert S.cell_side == pytest.approx(4 * 3 * a4)
    assert S.nominal_area == pytest.approx((12 * a4) ** 2)
    assert CellSettings(n_asperities=16).cell_side == pytest.approx(16 * a4)


def test_uniform_hertz_cell_matches_closed_form():
    g = torch.full((1, 9), 2.0, dtype=F64)
    h = torch.zeros(1, 9, dtype=F64)
    sw = sweep(g, h, S)
    d = sw.delta
    np.testing.assert_allclose(sw.p_star[0], 9 * 4 / 3 * d**1.5 / S.nominal_area, rtol=1e-10)
    np.testing.assert_allclose(sw.alpha[0], 9 * math.pi * d / S.nominal_area, rtol=1e-10)
    # S* = dP*/dalpha = (9 * 2 a) / (9 * pi) with a = sqrt(delta): S* = 2 sqrt(delta) / pi
    np.testing.assert_allclose(sw.stiffness[0], 2 * d.sqrt() / math.pi, rtol=1e-10, atol=1e-14)


def test_heights_shift_engagement_and_are_anchored():
    g = torch.tensor([[3.0, 3.0, 3.0, 3.0]], dtype=F64)
    h = torch.tensor([[0.005, 0.005, 0.015, 0.009]], dtype=F64)  # anchored: min h -> 0
    s4 = CellSettings(n_asperities=4)
    sw = sweep(g, h, s4)
    kc = float(kappa(torch.tensor(3.0, dtype=F64))) / 2  # c = 1/2 at R = 1
    d = sw.delta[:, None] - (h - h.min())[0][None]
    a = torch.clamp_min(d, 0) ** (1 / 3) * kc ** (-1 / 3)
    np.testing.assert_allclose(sw.alpha[0], math.pi * (a**2).sum(-1) / s4.nominal_area, rtol=1e-10)


def test_stiffness_matches_finite_differences_away_from_engagement():
    g, h = random_designs(4)
    sw = sweep(g, h, S, n_delta=4001)
    dp = torch.gradient(sw.p_star, spacing=(sw.delta,), dim=-1)[0]
    da = torch.gradient(sw.alpha, spacing=(sw.delta,), dim=-1)[0]
    fd = dp / da
    h0 = (h - h.min(-1, keepdim=True).values)[:, None, :]
    near = ((sw.delta[None, :, None] - h0).abs() < 2e-4).any(-1)  # within a few samples
    ok = ~near & (sw.delta[None] > 1e-3)
    np.testing.assert_allclose(sw.stiffness[ok], fd[ok], rtol=2e-3)


def test_stiffness_singularities_are_finite():
    # blunt (gamma > 2) asperity engaging while others carry load: S* -> 0; all finite
    g = torch.tensor([[2.0, 4.0, 1.8, 3.9]], dtype=F64)
    h = torch.tensor([[0.0, 0.01, 0.004, 0.0]], dtype=F64)
    s4 = CellSettings(n_asperities=4)
    delta = torch.tensor([0.0, 0.01, 0.01 + 1e-12, 0.004, 0.004 + 1e-15, 0.02], dtype=F64)
    sw = sweep(g, h, s4, delta=delta)
    assert torch.isfinite(sw.stiffness).all()
    assert float(sw.stiffness[0, 0]) == 0.0  # nothing carries load yet
    assert float(sw.stiffness[0, 2]) < 1e-3 * float(sw.stiffness[0, 1] + 1e-30) + 1e-4
    for smooth in (None, 1e3, 1e5):
        assert torch.isfinite(sweep(g, h, s4, smooth=smooth, n_delta=257).stiffness).all()


def test_permutation_invariance():
    g, h = random_designs(3, seed=1)
    perm = torch.randperm(9, generator=torch.Generator().manual_seed(2))
    a, b = curve(g, h, S), curve(g[:, perm], h[:, perm], S)
    np.testing.assert_allclose(a.alpha, b.alpha, rtol=1e-12)
    np.testing.assert_allclose(a.stiffness, b.stiffness, rtol=1e-12, atol=1e-15)


def test_gradcheck_float64():
    g, h = random_designs(2, seed=3)
    g.requires_grad_()
    h.requires_grad_()
    for smooth in (None, 1e3):

        def f(gg, hh, smooth=smooth):
            c = curve(gg, hh, CellSettings(n_steps=16), smooth=smooth)
            return c.alpha, c.p_star_max, c.alpha_max

        assert torch.autograd.gradcheck(f, (g, h), eps=1e-7, atol=1e-6, rtol=1e-4)


@pytest.mark.parametrize("smooth", [None, 1e3, 3e4])
def test_sweep_gradcheck_all_outputs(smooth):
    # the sweep's hand-written backward against finite differences, stiffness included
    g, h = random_designs(3, seed=11)
    g.requires_grad_()
    h.requires_grad_()

    def f(gg, hh):
        sw = sweep(gg, hh, S, smooth=smooth, n_delta=24)
        return sw.p_star, sw.alpha, sw.stiffness

    assert torch.autograd.gradcheck(f, (g, h), eps=1e-8, atol=1e-6, rtol=1e-4)


@pytest.mark.parametrize("dtype", [torch.float32, torch.float64])
@pytest.mark.parametrize("smooth", [None, 1e3, 1e5])
def test_gradients_finite_at_first_contact(dtype, smooth):
    # heights exactly on the Delta grid: asperities exactly at first contact
    grid = torch.linspace(0, S.delta_max, S.n_steps, dtype=dtype)
    g = torch.tensor([[1.8, 2.0, 4.0, 3.0, 2.5, 4.0, 1.8, 2.2, 3.3]], dtype=dtype)
    h = grid[[0, 0, 5, 17, 17, 40, 90, 127, 60]][None].clone()
    g.requires_grad_()
    h.requires_grad_()
    c = curve(g, h, S, smooth=smooth)
    loss = c.alpha_hat.sum() + c.stiffness_hat.sum() + c.p_star_max.log().sum()
    loss.backward()
    assert torch.isfinite(g.grad).all() and torch.isfinite(h.grad).all()
    assert torch.isfinite(c.stiffness).all()


def test_float32_matches_float64():
    g, h = random_designs(8, seed=4)
    c64 = curve(g, h, S)
    c32 = curve(g.float(), h.float(), S)
    np.testing.assert_allclose(c32.alpha_hat, c64.alpha_hat, atol=2e-5)
    np.testing.assert_allclose(c32.p_star_max, c64.p_star_max, rtol=1e-5)


def test_grid_and_normalised_forms():
    g, h = random_designs(5, seed=5)
    c = curve(g, h, S)
    sw = sweep(g, h, S)
    np.testing.assert_allclose(c.p_star_max, sw.p_star[:, -1])
    np.testing.assert_allclose(c.alpha_max, sw.alpha[:, -1])
    np.testing.assert_allclose(c.alpha_hat[:, -1], 1.0)
    assert float(c.alpha_hat[:, 0].abs().max()) == 0.0
    assert c.features().shape == (5, 2 * 128 + 2)
    # gridded alpha is the sweep's alpha interpolated at the grid pressures
    mid = c.p_star[:, 64:65]
    np.testing.assert_allclose(interp(mid, sw.p_star, sw.alpha), c.alpha[:, 64:65], rtol=1e-12)
    assert (c.alpha.diff(dim=-1) >= 0).all()


def test_softplus_curve_converges_to_exact():
    g, h = random_designs(4, seed=6)
    exact = curve(g, h, S).alpha_hat
    errs = [float((curve(g, h, S, smooth=k).alpha_hat - exact).abs().max()) for k in (1e3, 1e5)]
    # the softplus rounds the bracket over a width ln 2 / kappa_s, 100x narrower at 1e5; a
    # blunt (gamma = 4) asperity at engagement answers with area ~ delta^(1/2), so the worst
    # point falls by its square root, 10x, at least (measured 65x: 9.8 % -> 0.15 %)
    assert errs[1] < errs[0] / math.sqrt(100)


def test_interp_holds_ends_and_duplicate_knots():
    xp = torch.tensor([[0.0, 0.0, 1.0, 2.0]], dtype=F64)
    fp = torch.tensor([[5.0, 0.0, 1.0, 4.0]], dtype=F64)
    xq = torch.tensor([[-1.0, 0.0, 0.5, 1.5, 3.0]], dtype=F64)
    np.testing.assert_allclose(interp(xq, xp, fp), [[5.0, 5.0, 0.5, 2.5, 4.0]])


def test_window_mean_is_the_box_average_of_the_curve():
    # a line is its own box average inside; a step at x0 averages to the window's share
    # beyond it, a ramp of width 2 half; ends held; half -> 0 is the plain read
    xp = torch.tensor([[0.0, 1.0, 1.0, 3.0]], dtype=F64)
    fp = torch.tensor([[0.0, 1.0, 3.0, 5.0]], dtype=F64)  # slope 1, a jump of 2 at 1, slope 1
    xq = torch.tensor([[0.5, 0.95, 1.0, 1.1, 2.0, 3.0, -1.0]], dtype=F64)
    half = 0.2
    line = xq + 2.0 * ((xq + half - 1.0) / (2 * half)).clamp(0, 1)
    # held at the ends: [2.8, 3.2] has 0.2 at 5 beyond 3; [-1.2, -0.8] is all at 0
    expected = line.clone()
    expected[0, 5] = (0.2 * (4.8 + 5.0) / 2 + 0.2 * 5.0) / 0.4
    expected[0, 6] = 0.0
    np.testing.assert_allclose(window_mean(xq, half, xp, fp), expected, rtol=1e-12, atol=1e-15)
    off_step = [0, 1, 3, 4, 5]  # on the step itself the box average is the step's midpoint
    np.testing.assert_allclose(
        window_mean(xq, 1e-9, xp, fp)[:, off_step], interp(xq, xp, fp)[:, off_step], rtol=1e-7
    )
    # the read moves with the step: shifting the curve by s changes its box average by
    # -(f(x + half) - f(x - half)) / (2 half) ds, the step's jump of 2 included
    knots = xp.clone().requires_grad_()
    at = torch.tensor([[1.05]], dtype=F64)
    (grad,) = torch.autograd.grad(window_mean(at, half, knots, fp).sum(), knots)
    ends = interp(at + torch.tensor([[-half, half]], dtype=F64), xp, fp)[0]
    expected_shift = -float(ends[1] - ends[0]) / (2 * half)  # -(3.25 - 0.85) / 0.4
    assert float(grad.sum()) == pytest.approx(expected_shift, rel=1e-12)


@pytest.mark.parametrize(
    ("kwargs", "field"),
    [
        ({"n_asperities": 8}, "perfect square"),
        ({"gamma_min": 1.0}, "gamma_min"),
        ({"gamma_min": 3.0, "gamma_max": 2.0}, "gamma_min < gamma_max"),
        ({"delta_max": -0.01}, "delta_max"),
        ({"radius": float("nan")}, "radius"),
        ({"n_steps": 1}, "n_steps"),
    ],
)
def test_settings_validation(kwargs, field):
    with pytest.raises(MetainterfaceError, match=field):
        CellSettings(**kwargs)


def test_exact_alpha_at_given_loads_and_its_newton_load_match_hertz():
    # the exact law at given pressures solves P*(Delta) = p by Newton steps on the model's
    # newton_load (P* and dP*/dDelta alone for the independent model): both against Hertz,
    # P* = 9 (4/3) d^1.5 / A, dP*/dDelta = 9 (2 sqrt(d)) / A, alpha = 9 pi d / A
    from metainterface.physics.models import Independent

    g = torch.full((1, 9), 2.0, dtype=F64)
    h = torch.zeros(1, 9, dtype=F64)
    model = Independent()
    d = torch.linspace(1e-4, S.delta_max, 7, dtype=F64)[None]
    load = model.newton_load(g, h, S)(delta=d)
    np.testing.assert_allclose(load.p_star, 12 * d**1.5 / S.nominal_area, rtol=1e-12)
    np.testing.assert_allclose(load.load_slope, 18 * d.sqrt() / S.nominal_area, rtol=1e-12)
    p = 12 * d**1.5 / S.nominal_area
    alpha, p_max = model.alpha_at(g, h, S, p, exact=True)
    np.testing.assert_allclose(alpha, 9 * math.pi * d / S.nominal_area, rtol=1e-9)
    assert float(p_max[0]) == pytest.approx(12 * S.delta_max**1.5 / S.nominal_area, rel=1e-12)


@pytest.mark.parametrize("smooth", [None, 3e3])
@pytest.mark.parametrize("per_design_delta", [False, True])
def test_sweep_pullback_is_autograds_gradient(smooth, per_design_delta):
    # heights not anchored, the lowest anywhere: the pullback anchors them as sweep does
    from metainterface.physics.curves import sweep_pullback

    s = CellSettings()
    gen = torch.Generator().manual_seed(5)
    gamma = (1.5 + 2.5 * torch.rand(3, 9, generator=gen, dtype=torch.float64)).requires_grad_()
    h = (0.01 + 0.02 * torch.rand(3, 9, generator=gen, dtype=torch.float64)).requires_grad_()
    delta = torch.linspace(0, s.delta_max, 40, dtype=torch.float64)
    if per_design_delta:
        delta = delta * torch.rand(3, 1, generator=gen, dtype=torch.float64)
    g_p, g_a = torch.randn(2, 3, 40, generator=gen, dtype=torch.float64)
    sw = sweep(gamma, h, s, smooth=smooth, delta=delta)
    expected = torch.autograd.grad((sw.p_star * g_p + sw.alpha * g_a).sum(), (gamma, h))
    closed, back = sweep_pullback(gamma.detach(), h.detach(), s, smooth=smooth, delta=delta)
    torch.testing.assert_close(closed.p_star, sw.p_star.detach(), rtol=0, atol=0)
    torch.testing.assert_close(closed.alpha, sw.alpha.detach(), rtol=0, atol=0)
    for got, want in zip(back(g_p, g_a), expected, strict=True):
        torch.testing.assert_close(got, want, rtol=1e-13, atol=0)
