"""The batched L-BFGS against textbook forms."""

import torch

from metainterface.design.lbfgs import _direction, minimize


def test_two_loop_direction_equals_the_explicit_inverse_bfgs_update():
    # H_0 = (s.y / y.y of the newest valid pair) I, then for each valid pair, oldest first,
    # H <- (I - rho s y^T) H (I - rho y s^T) + rho s s^T; the direction is -H g. Row 1 has
    # its newest pair invalid (rho = 0): skipped, and the scale comes from the pair before.
    torch.manual_seed(0)
    b, d, pairs = 2, 5, 4
    g = torch.randn(b, d, dtype=torch.float64)
    hist = []
    for k in range(pairs):
        s = torch.randn(b, d, dtype=torch.float64)
        y = s + 0.3 * torch.randn(b, d, dtype=torch.float64)  # s.y > 0
        sy = (s * y).sum(-1)
        rho = 1.0 / sy
        if k == pairs - 1:
            rho[1] = 0.0
        hist.append((s, y, rho, sy / (y * y).sum(-1)))
    out = _direction(g, hist)
    eye = torch.eye(d, dtype=torch.float64)
    for row in range(b):
        valid = [(s[row], y[row], r[row], q[row]) for s, y, r, q in hist if r[row] > 0]
        h = valid[-1][3] * eye
        for s, y, rho, _ in valid:
            left = eye - rho * torch.outer(s, y)
            h = left @ h @ left.T + rho * torch.outer(s, s)
        torch.testing.assert_close(out[row], -h @ g[row], rtol=1e-12, atol=1e-12)


def test_rows_stop_at_the_loss_floor():
    # Row 0 reaches tol_loss at once (its minimum is 0), row 1 has a floor of 1 and runs on.
    def fun(x):
        return (x**2).sum(-1) + torch.tensor([0.0, 1.0], dtype=x.dtype)

    x0 = torch.tensor([[1e-4, 0.0], [3.0, -2.0]], dtype=torch.float64)
    res = minimize(fun, x0, tol_loss=1e-6, max_iter=50)
    torch.testing.assert_close(res.x[0], x0[0])  # already below 1e-6: never moved
    assert abs(res.loss[1].item() - 1.0) < 1e-10
