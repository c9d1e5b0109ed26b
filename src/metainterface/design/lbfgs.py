"""A batched L-BFGS: B independent minimisation problems advanced together.

``torch.optim.LBFGS`` treats its parameters as one problem: summing B losses would couple the
starts through a shared line search and shared curvature pairs. Here every row has its own
history, search direction, step length and convergence test, while the loss and gradients
of all rows are evaluated in one batched call.

Line search: per row, the strong Wolfe conditions (Armijo c1 = 1e-4, curvature c2 = 0.9)
are enforced by bracketing: a step that fails Armijo or overshoots to a rising slope shrinks
to the bracket's midpoint, a step that is too short doubles until bracketed, for at most
``max_ls`` evaluations; a row whose search fails keeps its last Armijo point, or stays put.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import torch
from torch import Tensor

C1, C2 = 1e-4, 0.9


@dataclass
class LbfgsResult:
    x: Tensor  # (B, D)
    loss: Tensor  # (B,)
    iterations: int
    evaluations: int


def _value_and_grad(fun: Callable[[Tensor], Tensor], x: Tensor) -> tuple[Tensor, Tensor]:
    x = x.detach().requires_grad_(True)
    f = fun(x)
    (g,) = torch.autograd.grad(f.sum(), x)
    f, g = f.detach(), g.detach()
    bad = ~torch.isfinite(f)
    f = torch.where(bad, torch.inf, f)
    g = torch.where(bad[:, None] | ~torch.isfinite(g), 0.0, g)
    return f, g


def _rows_value_and_grad(
    fun: Callable[[Tensor, Tensor], Tensor], x: Tensor, rows: Tensor
) -> tuple[Tensor, Tensor]:
    """Loss and gradient of the rows where ``rows`` (B,) is True; inf and 0 elsewhere."""
    idx = rows.nonzero().squeeze(1)
    f = torch.full_like(x[:, 0], torch.inf)
    g = torch.zeros_like(x)
    if idx.numel():
        f[idx], g[idx] = _value_and_grad(lambda z: fun(z, idx), x[idx])
    return f, g


def _direction(g: Tensor, hist: list[tuple[Tensor, Tensor, Tensor, Tensor]]) -> Tensor:
    """-H g by the two-loop recursion, per row; pairs with rho = 0 are skipped.

    hist: (s, y, rho, s.y / y.y) per pair, oldest first. The initial Hessian scale is the
    newest valid pair's s.y / y.y (1 if none). The batches are a few rows of ~17 numbers, so
    the cost is the number of tensor operations: fused ones (vecdot, addcmul_) and the scale
    picked in one pass over the stacked history, ~4 operations a pair instead of ~12.
    """
    q = g.clone()
    alphas = []
    for s, y, rho, _ in reversed(hist):
        a = rho * torch.linalg.vecdot(s, q)
        q.addcmul_(y, a[:, None], value=-1.0)
        alphas.append(a)
    scale = torch.ones_like(g[:, 0])
    if hist:
        rhos = torch.stack([h[2] for h in hist])  # (H, B)
        ratios = torch.stack([h[3] for h in hist])
        valid = rhos > 0
        # newest valid pair: the largest position among the valid ones
        pos = torch.arange(1, len(hist) + 1, device=g.device)[:, None]
        newest = (valid * pos).argmax(0, keepdim=True)
        scale = torch.where(valid.any(0), ratios.gather(0, newest)[0], scale)
    r = q * scale[:, None]
    for (s, y, rho, _), a in zip(hist, reversed(alphas), strict=True):
        b = rho * torch.linalg.vecdot(y, r)
        r.addcmul_(s, (a - b)[:, None])
    return -r


def minimize(
    fun: Callable[..., Tensor],
    x0: Tensor,
    *,
    indexed: bool = False,
    lr: float = 0.5,
    max_iter: int = 100,
    history: int = 10,
    tol_grad: float = 1e-7,
    tol_change: float = 1e-10,
    tol_loss: float = 1e-12,
    tol_stall: float = 0.0,
    stall_window: int = 5,
    max_ls: int = 8,
    max_failures: int = 3,
) -> LbfgsResult:
    """Minimise ``fun`` (B, D) -> (B,) row by row; returns the final points and losses.

    indexed: ``fun(x, idx)`` takes the rows ``idx`` (R,) of the batch, x (R, D), and returns
    their (R,) losses; the line search then evaluates only the rows still searching, so rows
    that have stopped cost nothing (with many starts, most stop long before the last).

    A row stops when its gradient is below ``tol_grad``, its loss below ``tol_loss``, an
    iteration changes its loss or its point by less than ``tol_change``, or (if ``tol_stall``
    > 0) its last ``stall_window`` iterations lowered its loss by less than the fraction
    ``tol_stall`` together, or ``max_failures`` line searches in a row end without a strong
    Wolfe point. The batch stops when no row is left.
    """

    def evaluate(x: Tensor, rows: Tensor) -> tuple[Tensor, Tensor]:
        """Loss and gradient at x; with ``indexed`` only the ``rows`` (B,) that are True."""
        return _rows_value_and_grad(fun, x, rows) if indexed else _value_and_grad(fun, x)

    x = x0.detach().clone()
    f, g = evaluate(x, torch.ones_like(x[:, 0], dtype=torch.bool))
    evals = 1
    active = (g.abs().amax(-1) > tol_grad) & (f > tol_loss)
    hist: list[tuple[Tensor, Tensor, Tensor, Tensor]] = []
    recent = [f]  # losses of the last stall_window iterations
    failures = torch.zeros_like(f, dtype=torch.long)  # consecutive failed line searches
    it = 0
    for it in range(1, max_iter + 1):
        if not active.any():
            break
        d = _direction(g, hist)
        gtd = (g * d).sum(-1)
        not_descent = gtd >= 0
        if not_descent.any():  # restart those rows on steepest descent
            d = torch.where(not_descent[:, None], -g, d)
            gtd = (g * d).sum(-1)
        if it == 1:
            t = lr * torch.clamp(1.0 / g.abs().sum(-1).clamp_min(1e-300), max=1.0)
        else:
            t = torch.full_like(f, lr)
        lo, hi = torch.zeros_like(t), torch.full_like(t, torch.inf)
        searching = active.clone()
        x_acc, f_acc, g_acc = x.clone(), f.clone(), g.clone()
        for _ in range(max_ls):
            x_try = torch.where(searching[:, None], x + t[:, None] * d, x_acc)
            f_try, g_try = evaluate(x_try, searching)
            evals += 1
            armijo = f_try <= f + C1 * t * gtd
            slope = (g_try * d).sum(-1)
            wolfe = armijo & (slope.abs() <= -C2 * gtd)
            improve = searching & armijo & (f_try < f_acc)
            x_acc = torch.where(improve[:, None], x_try, x_acc)
            f_acc = torch.where(improve, f_try, f_acc)
            g_acc = torch.where(improve[:, None], g_try, g_acc)
            searching = searching & ~wolfe
            if not searching.any():
                break
            shrink = ~armijo | (slope > 0)
            hi = torch.where(searching & shrink, t, hi)
            lo = torch.where(searching & ~shrink, t, lo)
            t = torch.where(torch.isinf(hi), 2 * t, 0.5 * (lo + hi))
        # a search that ends without a Wolfe point failed; three in a row stop the row
        failures = torch.where(searching, failures + 1, 0)
        s, y = x_acc - x, g_acc - g
        sy = (s * y).sum(-1)
        # a pair counts where its curvature is positive, relative to the step and gradient
        # change (scale-free: a polish at losses of 1e-8 has both tiny)
        valid = sy > 1e-10 * s.norm(dim=-1) * y.norm(dim=-1)
        rho = torch.where(valid, 1.0 / torch.where(valid, sy, 1.0), 0.0)
        hist.append((s, y, rho, sy / torch.linalg.vecdot(y, y).clamp_min(1e-300)))
        if len(hist) > history:
            hist.pop(0)
        moved = s.abs().amax(-1)
        change = (f - f_acc).abs()
        x, f, g = x_acc, f_acc, g_acc
        active = (
            active
            & (g.abs().amax(-1) > tol_grad)
            & (moved > tol_change)
            & (change > tol_change)
            & (f > tol_loss)
            & (failures < max_failures)
        )
        recent.append(f)
        if len(recent) > stall_window:
            old = recent.pop(0)
            if tol_stall > 0:
                active &= (old - f) > tol_stall * old
    return LbfgsResult(x, f, it, evals)
