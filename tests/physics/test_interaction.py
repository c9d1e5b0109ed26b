"""Interacting forward model: lattice kernels, limits, symmetry, tangent, gradients."""

import math

import numpy as np
import pytest
import torch

from metainterface.errors import MetainterfaceError
from metainterface.physics import (
    CellSettings,
    Design,
    curve,
    interp,
    kappa,
    pressures,
    sweep,
)
from metainterface.physics.interaction import (
    interaction,
    load_area_interacting,
    periodic_curvature,
    periodic_kernel,
    sweep_interacting,
)
from metainterface.physics.models import Independent, Interacting
from metainterface.physics.registry import MODELS, get_model

F64 = torch.float64
S = CellSettings()
MADELUNG_2D = -3.900264920001956  # regularised sum of 1/|m| over Z^2 \ {0}, neutralised
SUM_R3 = 9.033621683100950  # sum of 1/|m|^3 over Z^2 \ {0} = 4 zeta(3/2) beta(3/2)


def random_designs(b, n=9, seed=0, dtype=F64, settings=S):
    gen = torch.Generator().manual_seed(seed)
    g = settings.gamma_min + (settings.gamma_max - settings.gamma_min) * torch.rand(
        b, n, generator=gen, dtype=dtype
    )
    h = settings.delta_max * torch.rand(b, n, generator=gen, dtype=dtype)
    return g, h


# --- kernels ---------------------------------------------------------------------------


def test_kernel_constants_at_the_load_point():
    assert float(periodic_kernel(0.0, 0.0)) == pytest.approx(MADELUNG_2D, abs=1e-12)
    assert float(periodic_curvature(0.0, 0.0)) == pytest.approx(SUM_R3, abs=1e-12)
    # regularised: g(x) - 1/|x| is continuous at the load point
    for eps in (1e-3, 1e-4):
        assert float(periodic_kernel(eps, 0.0)) - 1 / eps == pytest.approx(MADELUNG_2D, abs=1e-5)


def test_kernel_periodic_and_symmetric():
    rng = np.random.default_rng(0)
    x, y = rng.uniform(-0.5, 0.5, (2, 50))
    g = periodic_kernel(x, y)
    for other in (
        periodic_kernel(x + 1, y),
        periodic_kernel(x, y - 2),
        periodic_kernel(-x, -y),
        periodic_kernel(y, x),
        periodic_kernel(-x, y),
    ):
        np.testing.assert_allclose(other, g, rtol=1e-12, atol=1e-12)
    c = periodic_curvature(x, y)
    np.testing.assert_allclose(periodic_curvature(x + 3, -y), c, rtol=1e-12)
    assert (c > 0).all()


def test_kernel_has_zero_cell_mean():
    # midpoint rule on a grid that avoids the load point; the integrable 1/r singularity
    # costs O(1/m) in the mean, against values of order 1-4
    m = 200
    u = (np.arange(m) + 0.5) / m - 0.5
    x, y = np.meshgrid(u, u)
    g = periodic_kernel(x, y)
    assert abs(g.mean()) < 0.02 * np.abs(g).mean()


def test_curvature_is_the_laplacian_of_the_kernel():
    x0, y0, e = 0.31, 0.17, 1e-3
    lap = (
        periodic_kernel(x0 + e, y0)
        + periodic_kernel(x0 - e, y0)
        + periodic_kernel(x0, y0 + e)
        + periodic_kernel(x0, y0 - e)
        - 4 * periodic_kernel(x0, y0)
    ) / e**2
    assert float(lap) == pytest.approx(float(periodic_curvature(x0, y0)), rel=1e-5)


def test_kernel_matches_direct_image_sum_of_differences():
    # the mean cancels in differences: g(x1) - g(x2) = sum over images of 1/r1 - 1/r2
    x1, x2 = np.array([0.2, 0.1]), np.array([0.45, -0.3])
    m = np.arange(-600, 601)
    mx, my = np.meshgrid(m, m)
    d = 1 / np.hypot(x1[0] + mx, x1[1] + my) - 1 / np.hypot(x2[0] + mx, x2[1] + my)
    # images beyond the square |m| <= 600 (half-width 600.5): the angular mean of the
    # difference is (|x1|^2 - |x2|^2) / (4 r^3), and the integral of 1/r^3 outside a square
    # of half-width w is 4 sqrt(2) / w
    tail = (x1 @ x1 - x2 @ x2) / 4 * 4 * math.sqrt(2) / 600.5
    direct = d.sum() + tail
    assert float(periodic_kernel(*x1) - periodic_kernel(*x2)) == pytest.approx(direct, abs=2e-6)


@pytest.mark.parametrize("n_asp", [4, 9, 16])
def test_interaction_matrices(n_asp):
    s = CellSettings(n_asperities=n_asp)
    n = s.n_side
    kern = interaction(s)
    k, c = kern.shift.numpy(), kern.curvature.numpy()
    np.testing.assert_allclose(k, k.T, atol=1e-15)
    np.testing.assert_allclose(c, c.T, rtol=1e-14)
    np.testing.assert_allclose(k.sum(axis=1), 0.0, atol=1e-14)  # zero mean on the lattice
    assert (c > 0).all()
    # circulant: the entry depends only on the lattice offset (torus)
    for i, j in [(0, 1), (1, (n + 2) % n_asp), (n_asp - 1, 0)]:
        di, dj = divmod(i, n), divmod(j, n)
        i2 = ((di[0] + 1) % n) * n + (di[1] + 1) % n
        j2 = ((dj[0] + 1) % n) * n + (dj[1] + 1) % n
        assert k[i2, j2] == pytest.approx(k[i, j], abs=1e-14)
    # the neighbour's lowering relative to the loaded tip: ~ 1 / (pi E* p), p = 4 a_max
    p = s.cell_side / n
    assert 0.9 < (k[1, 0] - k[0, 0]) * math.pi * p < 1.4  # 2x2: images on both sides
    # scaling with the pitch
    far = interaction(s, pitch=10 * p)
    np.testing.assert_allclose(far.shift.numpy() * 10, k, rtol=1e-12, atol=1e-16)
    np.testing.assert_allclose(far.curvature.numpy() * 1000, c, rtol=1e-12)


def test_single_asperity_has_no_shift_kernel():
    kern = interaction(CellSettings(n_asperities=1))
    assert float(kern.shift.abs().max()) == 0.0
    s1 = CellSettings(n_asperities=1)
    assert float(kern.curvature[0, 0]) == pytest.approx(SUM_R3 / (4 * math.pi * s1.cell_side**3))


# --- limits ----------------------------------------------------------------------------


@pytest.mark.parametrize("smooth", [None, 1e3])
def test_zero_kernel_is_the_independent_model(smooth):
    g, h = random_designs(5, seed=1)
    a = sweep_interacting(g, h, S, smooth=smooth, kernel=interaction(S).scaled(0.0))
    b = sweep(g, h, S, smooth=smooth)
    np.testing.assert_allclose(a.p_star, b.p_star, rtol=1e-12, atol=1e-18)
    np.testing.assert_allclose(a.alpha, b.alpha, rtol=1e-12, atol=1e-18)
    np.testing.assert_allclose(a.stiffness, b.stiffness, rtol=1e-10, atol=1e-15)


def test_far_apart_tends_to_the_independent_model():
    g, h = random_designs(4, seed=2)
    ind = sweep(g, h, S)
    p = S.cell_side / S.n_side
    errs = []
    for factor in (10.0, 100.0):
        a = sweep_interacting(g, h, S, kernel=interaction(S, pitch=factor * p))
        errs.append(float((a.alpha - ind.alpha).abs().max() / ind.alpha.max()))
    assert errs[1] < 2e-3
    # the shift decays like 1 / pitch; a blunt (gamma = 4) asperity at engagement answers
    # with area ~ delta^(1/2), so the worst point decays like pitch^(-1/2) at least
    assert errs[1] < errs[0] / math.sqrt(10) * 1.2


def test_single_asperity_closed_form():
    # N = 1: no shift; the images curve the surface by b = C F, and Sneddon for
    # c r^gamma + b r^2 gives F = E* (2 gamma/(gamma+1) kappa c a^(gamma+1) + 8/3 b a^3)
    s1 = CellSettings(n_asperities=1)
    c11 = SUM_R3 / (4 * math.pi * s1.cell_side**3)
    for gam in (1.8, 2.0, 3.0, 4.0):
        g = torch.tensor([[gam]], dtype=F64)
        h = torch.zeros(1, 1, dtype=F64)
        sw = sweep_interacting(g, h, s1, iterations=12, curvature=True)
        a = torch.sqrt(sw.alpha[0] * s1.nominal_area / math.pi)
        kc = float(kappa(torch.tensor(gam, dtype=F64))) / 2
        f0 = 2 * gam / (gam + 1) * kc * a ** (gam + 1)
        force = f0 / (1 - 8 / 3 * c11 * a**3)
        np.testing.assert_allclose(sw.p_star[0] * s1.nominal_area, force, rtol=1e-9, atol=1e-18)
        # and without the curvature (the default) it is the independent model exactly
        ind = sweep_interacting(g, h, s1)
        ref = sweep(g, h, s1)
        np.testing.assert_allclose(ind.alpha, ref.alpha, rtol=1e-12)


@pytest.mark.parametrize("curvature", [True, False])
def test_uniform_cells_are_one_asperity_cells(curvature):
    # identical asperities: by symmetry every tip sees the same field, w = 0, and the cell
    # behaves as the N = 1 cell of the same pitch (whatever N)
    for gam in (1.8, 2.5, 4.0):
        curves = []
        for n_asp in (1, 9, 16):
            s = CellSettings(n_asperities=n_asp)
            g = torch.full((1, n_asp), gam, dtype=F64)
            h = torch.zeros(1, n_asp, dtype=F64)
            curves.append(sweep_interacting(g, h, s, iterations=10, curvature=curvature))
        for other in curves[1:]:
            np.testing.assert_allclose(other.p_star, curves[0].p_star, rtol=1e-7)
            np.testing.assert_allclose(other.alpha, curves[0].alpha, rtol=1e-7)
    # equal heights but different shapes break the symmetry
    g = torch.tensor([[2.0, 4.0, 2.0, 4.0, 2.0, 4.0, 2.0, 4.0, 2.0]], dtype=F64)
    a = sweep_interacting(g, torch.zeros(1, 9, dtype=F64), S, curvature=curvature)
    b = sweep(g, torch.zeros(1, 9, dtype=F64), S)
    assert float((a.alpha - b.alpha).abs().max()) > 1e-3 * float(b.alpha.max())


def test_lattice_symmetries_leave_the_response_unchanged():
    g, h = random_designs(3, seed=3)
    base = sweep_interacting(g, h, S)
    idx = torch.arange(9).view(3, 3)
    for perm in (
        idx.roll(1, 0).flatten(),  # translation on the torus
        idx.roll(2, 1).flatten(),
        idx.T.flatten(),  # reflection in the diagonal
        idx.flip(0).flatten(),  # mirror
    ):
        other = sweep_interacting(g[:, perm], h[:, perm], S)
        np.testing.assert_allclose(other.alpha, base.alpha, rtol=1e-12)
        np.testing.assert_allclose(other.p_star, base.p_star, rtol=1e-12)


def test_neighbours_delay_a_blunt_asperity():
    # a sphere at h = 0 next to a gamma = 4 asperity set back by 5e-3: the sphere's load lowers
    # the surface at the blunt tip, which touches later than in superposition
    s4 = CellSettings(n_asperities=4)
    g = torch.tensor([[2.0, 4.0, 2.0, 2.0]], dtype=F64)
    h = torch.tensor([[0.0, 0.005, 0.02, 0.02]], dtype=F64)
    delta = torch.linspace(0, 0.02, 2001, dtype=F64)
    ind = sweep(g, h, s4, delta=delta)
    inter = sweep_interacting(g, h, s4, delta=delta)
    # engagement: the stiffness drops to ~0 when the gamma = 4 asperity comes in
    first = int(torch.nonzero(ind.stiffness[0, 1:] < 0.5 * ind.stiffness[0, :-1])[0]) + 1
    later = int(torch.nonzero(inter.stiffness[0, 1:] < 0.5 * inter.stiffness[0, :-1])[0]) + 1
    assert later > first
    # at equal load the blunt asperity has less area
    p = ind.p_star[:, first + 100 : first + 101]
    assert float(interp(p, inter.p_star, inter.alpha)) < float(interp(p, ind.p_star, ind.alpha))


# --- solve, tangent, gradients ---------------------------------------------------------


@pytest.mark.parametrize("curvature", [True, False])
def test_fixed_point_converges(curvature):
    g, h = random_designs(16, seed=4)
    ref = sweep_interacting(g, h, S, iterations=30, curvature=curvature)
    out = sweep_interacting(g, h, S, curvature=curvature)
    atol = 1e-6 * float(ref.alpha.max())
    np.testing.assert_allclose(out.alpha, ref.alpha, rtol=2e-3, atol=atol)
    more = sweep_interacting(g, h, S, iterations=8, curvature=curvature)
    np.testing.assert_allclose(more.alpha, ref.alpha, rtol=1e-9)
    np.testing.assert_allclose(more.stiffness, ref.stiffness, rtol=1e-6, atol=1e-12)


def test_tip_shift_only():
    # without the curvature term identical asperities are exactly the paper's model; the
    # curvature lowers their alpha at given load (it adds b r^2 >= 0 to every profile)
    g = torch.full((1, 9), 3.0, dtype=F64)
    h = torch.zeros(1, 9, dtype=F64)
    a = sweep_interacting(g, h, S)  # the default
    b = sweep(g, h, S)
    np.testing.assert_allclose(a.alpha, b.alpha, rtol=1e-12)
    np.testing.assert_allclose(a.stiffness, b.stiffness, rtol=1e-9)
    full = sweep_interacting(g, h, S, curvature=True)
    p = a.p_star[:, 20:]
    assert (interp(p, full.p_star, full.alpha) < a.alpha[:, 20:]).all()
    assert interaction(S, curvature=False).curvature is None


def test_stiffness_matches_finite_differences():
    g, h = random_designs(4, seed=5)
    sw = sweep_interacting(g, h, S, n_delta=4001, iterations=10)
    dp = torch.gradient(sw.p_star, spacing=(sw.delta,), dim=-1)[0]
    da = torch.gradient(sw.alpha, spacing=(sw.delta,), dim=-1)[0]
    fd = dp / da
    # away from engagements (kinks of the curve) central differences are second order
    smooth = (sw.stiffness[:, 2:] - 2 * sw.stiffness[:, 1:-1] + sw.stiffness[:, :-2]).abs()
    ok = torch.zeros_like(fd, dtype=torch.bool)
    ok[:, 1:-1] = smooth < 1e-3 * sw.stiffness[:, 1:-1].abs()
    ok &= sw.delta[None] > 1e-3
    assert ok.float().mean() > 0.8
    np.testing.assert_allclose(sw.stiffness[ok], fd[ok], rtol=1e-3)


@pytest.mark.parametrize("curvature", [True, False])
def test_gradcheck_float64(curvature):
    s4 = CellSettings(n_asperities=4)
    g, h = random_designs(1, n=4, seed=6, settings=s4)
    g.requires_grad_()
    h.requires_grad_()
    for smooth in (None, 1e3):

        def f(gg, hh, smooth=smooth):
            sw = sweep_interacting(gg, hh, s4, smooth=smooth, n_delta=10, curvature=curvature)
            return sw.alpha, sw.p_star, sw.stiffness

        assert torch.autograd.gradcheck(f, (g, h), eps=1e-7, atol=1e-6, rtol=1e-4)


@pytest.mark.parametrize("dtype", [torch.float32, torch.float64])
@pytest.mark.parametrize("smooth", [None, 1e3, 1e5])
def test_gradients_finite_at_first_contact(dtype, smooth):
    grid = torch.linspace(0, S.delta_max, S.n_steps, dtype=dtype)
    g = torch.tensor([[1.8, 2.0, 4.0, 3.0, 2.5, 4.0, 1.8, 2.2, 3.3]], dtype=dtype)
    h = grid[[0, 0, 5, 17, 17, 40, 90, 127, 60]][None].clone()
    g.requires_grad_()
    h.requires_grad_()
    c = Interacting().curve(g, h, S, smooth=smooth)
    loss = c.alpha_hat.sum() + c.stiffness_hat.sum() + c.p_star_max.log().sum()
    loss.backward()
    assert torch.isfinite(g.grad).all() and torch.isfinite(h.grad).all()
    assert torch.isfinite(c.stiffness).all() and torch.isfinite(c.alpha).all()


def test_float32_matches_float64():
    g, h = random_designs(8, seed=7)
    c64 = Interacting().curve(g, h, S)
    c32 = Interacting().curve(g.float(), h.float(), S)
    np.testing.assert_allclose(c32.alpha_hat, c64.alpha_hat, atol=5e-5)
    np.testing.assert_allclose(c32.p_star_max, c64.p_star_max, rtol=1e-5)


# --- the registry ----------------------------------------------------------------------


def test_registry():
    assert tuple(MODELS) == ("independent", "interacting")
    assert get_model() == Independent() and get_model("interacting") == Interacting()
    with pytest.raises(MetainterfaceError, match="model must be one of"):
        get_model("coupled")
    g, h = random_designs(2, seed=8)
    np.testing.assert_array_equal(Independent().sweep(g, h, S).alpha, sweep(g, h, S).alpha)
    np.testing.assert_array_equal(
        Interacting().sweep(g, h, S).alpha, sweep_interacting(g, h, S).alpha
    )
    np.testing.assert_allclose(get_model().curve(g, h, S).alpha, curve(g, h, S).alpha)
    sw = sweep_interacting(g, h, S, smooth=1e3)
    delta, p, a = load_area_interacting(g, h, S, smooth=1e3)
    np.testing.assert_array_equal(delta, sw.delta)
    np.testing.assert_array_equal(p, sw.p_star)
    np.testing.assert_array_equal(a, sw.alpha)
    d = Design(gamma=g[0].numpy(), h=h[0].numpy())
    sw = Interacting().design_sweep(d, n_delta=32)
    assert sw.alpha.shape == (1, 32)


def test_alpha_at_matches_the_design_convention():
    g, h = random_designs(3, seed=9)
    p = torch.linspace(0, 0.004, 50, dtype=F64)[None].expand(3, -1)
    a, p_max = Independent().alpha_at(g, h, S, p)
    ref = pressures.alpha_at(g, h, S, p)
    np.testing.assert_array_equal(a, ref[0])
    np.testing.assert_array_equal(p_max, ref[1])
    a, p_max = Interacting().alpha_at(g, h, S, p)
    sw = sweep_interacting(g, h, S)
    np.testing.assert_allclose(p_max, sw.p_star[:, -1])
    beyond = p > p_max[:, None]
    assert beyond.any()  # held at the last value beyond P*_max
    np.testing.assert_allclose(a[beyond], sw.alpha[:, -1:].expand(-1, 50)[beyond])


def test_alpha_at_loads_extends_the_sweep():
    # the interacting model reaches a different P* at Delta_max than the paper's (here: a
    # higher one); alpha_at_loads runs each sweep as far as the loads need
    g, h = random_designs(8, seed=11)
    top_ind = sweep(g, h, S).p_star[:, -1]
    top_int = sweep_interacting(g, h, S).p_star[:, -1]
    i = int(torch.argmax(top_int / top_ind))
    g, h = g[i : i + 1], h[i : i + 1]
    assert float(top_int[i]) > 1.01 * float(top_ind[i])
    loads = top_int[i] * torch.tensor([[0.25, 0.5, 0.75, 1.0]], dtype=F64)
    a_ind = Independent().alpha_at_loads(g, h, S, loads)
    long = torch.linspace(0, 2 * S.delta_max, 8193, dtype=F64)
    dense = sweep(g, h, S, delta=long)
    np.testing.assert_allclose(a_ind, interp(loads, dense.p_star, dense.alpha), rtol=1e-5)
    a_int = Interacting().alpha_at_loads(g, h, S, loads)
    ref = sweep_interacting(g, h, S, delta=long)
    np.testing.assert_allclose(a_int, interp(loads, ref.p_star, ref.alpha), rtol=1e-5)
    with pytest.raises(MetainterfaceError, match="not reached"):
        Independent().alpha_at_loads(g, h, S, loads * 1e6, max_extend=1)


def test_curvature_lowers_blunt_uniform_cells():
    # identical gamma = 4 asperities: the images' curvature lowers alpha at given P* by
    # -0.8 % at half and -1.2 % at full load of the paper's P*_max (closed form of the N = 1
    # test, reached past Delta_max since P*_max drops too)
    g = torch.full((1, 9), 4.0, dtype=F64)
    h = torch.zeros(1, 9, dtype=F64)
    ind = sweep(g, h, S, n_delta=8193)
    loads = ind.p_star[:, -1:] * torch.tensor([[0.5, 1.0]], dtype=F64)
    long = torch.linspace(0, 1.5 * S.delta_max, 8193, dtype=F64)
    full = sweep_interacting(g, h, S, delta=long, curvature=True)
    assert float(interp(loads[:, 1:], full.delta[None], full.p_star)) < float(loads[0, 1])
    rel = (interp(loads, full.p_star, full.alpha) / interp(loads, ind.p_star, ind.alpha) - 1)[0]
    assert -0.0125 < float(rel[1]) < -0.0115 and -0.0083 < float(rel[0]) < -0.0075
