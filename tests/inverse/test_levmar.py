"""The batched Levenberg-Marquardt, and the exact-law residuals it polishes with."""

import pytest
import torch

from metainterface.inverse import builtin_target
from metainterface.inverse.levmar import least_squares
from metainterface.inverse.losses import TargetGrid, masked_loss, residuals
from metainterface.inverse.params import FULL, HERTZ
from metainterface.physics import CellSettings

F64 = torch.float64


def rosenbrock(a: torch.Tensor):
    """Residuals (a - x0, 10 (x1 - x0^2)) per row: minimum 0 at (a, a^2)."""

    def fun(x, idx):
        r = torch.stack([a[idx] - x[:, 0], 10 * (x[:, 1] - x[:, 0] ** 2)], -1)
        jac = torch.zeros(x.shape[0], 2, 2, dtype=F64)
        jac[:, 0, 0] = -1.0
        jac[:, 1, 0] = -20 * x[:, 0]
        jac[:, 1, 1] = 10.0
        return r, jac

    return fun


def test_rosenbrock_rows_reach_their_own_minimum():
    a = torch.tensor([1.0, 2.0, -0.5], dtype=F64)
    res = least_squares(rosenbrock(a), torch.zeros(3, 2, dtype=F64), max_iter=100, tol_loss=1e-24)
    torch.testing.assert_close(res.x, torch.stack([a, a**2], 1), rtol=0, atol=1e-9)
    assert res.iterations < 60


def test_a_linear_problem_is_solved_by_the_normal_equations():
    # r = A x - b: Gauss-Newton's first step is the least-squares solution; the damping
    # (1e-3 relative) leaves it within a few steps of it
    gen = torch.Generator().manual_seed(0)
    a = torch.randn(2, 12, 4, generator=gen, dtype=F64)
    b = torch.randn(2, 12, generator=gen, dtype=F64)
    expected = torch.linalg.lstsq(a, b[..., None]).solution[..., 0]

    def fun(x, idx):
        return (a[idx] @ x[..., None])[..., 0] - b[idx], a[idx]

    res = least_squares(fun, torch.zeros(2, 4, dtype=F64), tol_stall=1e-14, max_iter=20)
    torch.testing.assert_close(res.x, expected, rtol=0, atol=1e-9)


def test_rows_are_independent_and_stopped_rows_are_not_evaluated():
    a = torch.tensor([1.0, 3.0], dtype=F64)
    seen = []
    fun = rosenbrock(a)

    def logged(x, idx):
        seen.append(idx.tolist())
        return fun(x, idx)

    x0 = torch.tensor([[1.0, 1.0], [0.0, 0.0]], dtype=F64)  # row 0 starts at its minimum
    both = least_squares(logged, x0, max_iter=30)
    assert all(0 not in rows for rows in seen[1:])
    alone = least_squares(lambda x, idx: fun(x, idx + 1), x0[1:], max_iter=30)
    torch.testing.assert_close(both.x[1:], alone.x, rtol=0, atol=0)


def test_steps_are_cut_to_max_step_and_ignored_parameters_stay_finite():
    # x1 does not enter the residual (a zero column of J); x0's Gauss-Newton step is 10
    def fun(x, idx):
        jac = torch.zeros(x.shape[0], 1, 2, dtype=F64)
        jac[:, 0, 0] = 1.0
        return x[:, :1] - 10.0, jac

    res = least_squares(fun, torch.zeros(1, 2, dtype=F64), max_iter=1, max_step=0.25)
    torch.testing.assert_close(res.x, torch.tensor([[0.25, 0.0]], dtype=F64))


@pytest.mark.parametrize("hertz", [False, True])
def test_residuals_are_the_exact_loss_and_their_jacobian_its_gradient(hertz):
    s = CellSettings()
    targets = [builtin_target(n) for n in ("saturating", "bilinear")]
    grid = TargetGrid.from_curves([(t.p_star, t.alpha) for t in targets], 32)
    gen = torch.Generator().manual_seed(1)
    raw = torch.randn(2, 8 if hertz else 17, generator=gen, dtype=F64) - 1.0
    param = HERTZ if hertz else FULL
    r, jac = residuals(raw, s, grid, 0.1, param=param)
    z = raw.clone().requires_grad_(True)
    loss = masked_loss(*param.to_design(z, s), s, grid, None, 0.1)
    torch.testing.assert_close((r * r).sum(-1), loss.detach(), rtol=1e-12, atol=0)
    (grad,) = torch.autograd.grad(loss.sum(), z)
    torch.testing.assert_close(2 * (jac.mT @ r[..., None])[..., 0], grad, rtol=1e-9, atol=1e-15)
    # and against central differences, column by column
    eps = 1e-6
    for k in range(raw.shape[1]):
        step = torch.zeros_like(raw)
        step[:, k] = eps
        diff = (
            residuals(raw + step, s, grid, 0.1, param=param)[0]
            - residuals(raw - step, s, grid, 0.1, param=param)[0]
        ) / (2 * eps)
        torch.testing.assert_close(jac[:, :, k], diff, rtol=1e-4, atol=1e-7)


def test_the_polish_is_never_worse_than_the_lbfgs_polish():
    # The linear law is not realisable: Levenberg-Marquardt stops above the design tolerance
    # and the L-BFGS polish runs from the same start; the better of the two is kept.
    from metainterface.inverse.refine import RefineSettings, polish, refine

    s = CellSettings()
    target = builtin_target("linear")
    grid = TargetGrid.from_curves([(target.p_star, target.alpha)] * 2, 64)
    gen = torch.Generator().manual_seed(3)
    raw = torch.randn(2, 17, generator=gen, dtype=F64) - 1.0
    rs = RefineSettings(polish_iterations=20)

    def loss(x):
        return masked_loss(*FULL.to_design(x, s), s, grid, None, rs.undershoot_weight)

    both = loss(polish(raw, s, grid, rs))
    lbfgs_only = loss(refine(raw, s, grid, rs.polishing()))
    assert (both <= lbfgs_only).all()
    assert (both < loss(raw)).all()


def test_an_unknown_polish_method_is_refused_by_name():
    from metainterface.errors import MetainterfaceError
    from metainterface.inverse.refine import RefineSettings

    with pytest.raises(MetainterfaceError, match="polish_method must be one of levmar, lbfgs"):
        RefineSettings(polish_method="newton")
