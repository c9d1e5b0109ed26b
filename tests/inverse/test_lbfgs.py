"""The batched L-BFGS against textbook forms."""

import pytest
import torch

from metainterface.inverse.lbfgs import History, minimize


def explicit_direction(g: torch.Tensor, window: list[tuple[torch.Tensor, torch.Tensor]]):
    """-H g of one row by the explicit inverse BFGS update: H_0 = (s.y / y.y of the newest
    valid pair) I, 1 if none, then for each valid pair, oldest first,
    H <- (I - rho s y^T) H (I - rho y s^T) + rho s s^T. Valid: s.y > 1e-10 |s| |y|."""
    valid = [(s, y) for s, y in window if s @ y > 1e-10 * s.norm() * y.norm()]
    eye = torch.eye(len(g), dtype=g.dtype)
    h = (valid[-1][0] @ valid[-1][1] / (valid[-1][1] @ valid[-1][1]) if valid else 1.0) * eye
    for s, y in valid:
        rho = 1.0 / (s @ y)
        left = eye - rho * torch.outer(s, y)
        h = left @ h @ left.T + rho * torch.outer(s, s)
    return -h @ g


@pytest.mark.parametrize("scale", [1.0, 1e-6])
def test_compact_direction_equals_the_explicit_inverse_bfgs_update(scale):
    # Pushes one pair at a time into a history of 4 and checks every row's direction after
    # each: fewer pairs than the history, then the window sliding (the buffer's pairs move
    # to its front after 4 pushes, then every 5). Each row gets its own pattern of invalid
    # pairs (s.y < 0): row 0 none, row 1 every third (in the middle of the window, and the
    # newest), row 2 a run of 5 so its window empties (the scale falls back to 1) and fills
    # again.
    # scale 1e-6: steps and gradient changes of a polish at losses of ~1e-12.
    torch.manual_seed(0)
    b, d, m, pushes = 3, 5, 4, 17
    invalid = [set(), set(range(2, pushes, 3)), {3, 4, 5, 6, 7}]
    hist = History(torch.zeros(b, d, dtype=torch.float64), m)
    pairs = []
    for k in range(pushes):
        s = scale * torch.randn(b, d, dtype=torch.float64)
        y = s + 0.3 * scale * torch.randn(b, d, dtype=torch.float64)  # s.y > 0
        for row in range(b):
            if k in invalid[row]:
                y[row] = -y[row]
        x, g0 = torch.randn(b, d, dtype=torch.float64), torch.randn(b, d, dtype=torch.float64)
        x_new, g_new = x + s, g0 + y
        moved = hist.push(x_new, x, g_new, g0)
        s, y = x_new - x, g_new - g0  # the pair as pushed
        assert torch.equal(moved, s.abs().amax(-1))
        pairs.append((s, y))
        g = torch.randn(b, d, dtype=torch.float64)
        out = hist.direction(g)
        for row in range(b):
            window = [(s[row], y[row]) for s, y in pairs[-m:]]
            expected = explicit_direction(g[row], window)
            torch.testing.assert_close(out[row], expected, rtol=1e-10, atol=0)


def test_no_history_is_steepest_descent():
    g = torch.randn(2, 3, dtype=torch.float64)
    torch.testing.assert_close(History(g, 5).direction(g), -g)


def test_rows_stop_at_the_loss_floor():
    # Row 0 reaches tol_loss at once (its minimum is 0), row 1 has a floor of 1 and runs on.
    def fun(x):
        return (x**2).sum(-1) + torch.tensor([0.0, 1.0], dtype=x.dtype)

    x0 = torch.tensor([[1e-4, 0.0], [3.0, -2.0]], dtype=torch.float64)
    res = minimize(fun, x0, tol_loss=1e-6, max_iter=50)
    torch.testing.assert_close(res.x[0], x0[0])  # already below 1e-6: never moved
    assert abs(res.loss[1].item() - 1.0) < 1e-10


def quadratics(conds: list[float], d: int, seed: int = 0):
    """Row-wise 0.5 (x - c)^T A (x - c), row i's A with eigenvalues 1..conds[i]."""
    gen = torch.Generator().manual_seed(seed)
    b = len(conds)
    q, _ = torch.linalg.qr(torch.randn(b, d, d, generator=gen, dtype=torch.float64))
    eig = torch.stack([torch.logspace(0, torch.log10(torch.tensor(c)), d) for c in conds])
    a = q @ torch.diag_embed(eig.to(torch.float64)) @ q.mT
    c = torch.randn(b, d, generator=gen, dtype=torch.float64)

    def fun(x, idx=None):
        a_, c_ = (a, c) if idx is None else (a[idx], c[idx])
        z = (x - c_)[:, :, None]
        return 0.5 * (z.mT @ a_ @ z)[:, 0, 0]

    return fun, c


@pytest.mark.parametrize("indexed", [False, True])
def test_rows_are_independent(indexed):
    # Every row alone follows the trajectory it follows in the batch: rows 0 and 1 (well
    # conditioned) stop early, rows 2 and 3 are still on their way after 40 iterations.
    fun, c = quadratics([1.0, 10.0, 1e3, 1e3], 8)
    x0 = torch.zeros(4, 8, dtype=torch.float64)
    kw = {"indexed": indexed, "history": 4, "max_iter": 40, "lr": 1.0, "tol_grad": 1e-9}
    res = minimize(fun, x0, **kw)
    error = (res.x - c).abs().amax(-1)
    assert (error[:2] < 1e-5).all() and (error[2:] > 1e-3).all()
    for row in range(4):

        def one(x, idx=None, row=row):
            return fun(x, torch.tensor([row]))

        alone = minimize(one, x0[row : row + 1], **kw)
        torch.testing.assert_close(alone.x[0], res.x[row], rtol=1e-10, atol=1e-14)
        torch.testing.assert_close(alone.loss[0], res.loss[row], rtol=1e-10, atol=1e-24)
        assert alone.iterations < kw["max_iter"] if row < 2 else alone.iterations == 40


def test_non_finite_losses_are_stepped_around():
    # Walls of NaN (row 0) and -inf (row 1) just beyond the minimum at 0.9: the first step
    # lands behind them, the line search shrinks back, and the minimum is reached.
    hits = []

    def fun(x):
        f = ((x - 0.9) ** 2).sum(-1)
        hits.append(((x[:, 0] > 1.0) | (x[:, 1] > 1.0)).sum().item())
        f = torch.where(x[:, 0] > 1.0, torch.nan, f)
        return torch.where(x[:, 1] > 1.0, -torch.inf, f)

    x0 = torch.tensor([[-3.0, 0.9], [0.9, -3.0]], dtype=torch.float64)
    res = minimize(fun, x0, lr=8.0)
    assert hits[1] == 2  # the first line search's first step: both rows behind their wall
    torch.testing.assert_close(res.x, torch.full_like(x0, 0.9), rtol=0, atol=1e-5)
    assert (res.loss < 1e-10).all()


def test_rows_stop_after_max_failures_line_searches():
    # Row 0's gradient points uphill (its loss is x_0, the gradient reads -1): no step passes
    # Armijo, so every line search fails, and after max_failures the row stops, unmoved and
    # no longer evaluated (tol_change off: not moving would stop it at once). Row 1 is an
    # ordinary bowl.
    seen = []

    def fun(x, idx):
        seen.append(idx.tolist())
        uphill = 2 * x.detach()[:, 0] - x[:, 0]
        return torch.where(idx == 0, uphill, (x**2).sum(-1))

    x0 = torch.tensor([[1.0, 2.0], [1.0, 2.0]], dtype=torch.float64)
    res = minimize(fun, x0, indexed=True, max_ls=4, max_failures=3, tol_change=-1.0)
    assert sum(0 in rows for rows in seen) == 1 + 3 * 4
    torch.testing.assert_close(res.x[0], x0[0], rtol=0, atol=0)
    assert res.loss[1].item() < 1e-12
