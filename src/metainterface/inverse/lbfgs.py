"""A batched L-BFGS: B independent minimisation problems advanced together.

``torch.optim.LBFGS`` treats its parameters as one problem: summing B losses would couple the
starts through a shared line search and shared curvature pairs. Here every row has its own
history, search direction, step length and convergence test, while the loss and gradients
of all rows are evaluated in one batched call.

Line search: per row, the strong Wolfe conditions (Armijo c1 = 1e-4, curvature c2 = 0.9)
are enforced by bracketing: a step that fails Armijo or overshoots to a rising slope shrinks
to the bracket's midpoint, a step that is too short doubles until bracketed, for at most
``max_ls`` evaluations; a row whose search fails keeps its last Armijo point, or stays put.

The batches are a few rows of ~17 numbers, so the cost is the number of tensor operations
(a few microseconds each), not their flops: the history is kept as stacked tensors and the
direction taken in the compact form, ~15 batched operations for any history length, and
the line search and bookkeeping use as few (fused) operations as the rules allow.
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
    """Loss (B,) and gradient (B, D) at x (B, D). A non-finite loss reads inf, non-finite
    gradient entries read 0. Rows with an inf loss keep their (finite) gradient instead of
    zeros, an operation less per evaluation: no line search accepts an inf loss, so it is
    never used (``minimize`` zeroes it after the first evaluation, which it does use).
    """
    x = x.detach().requires_grad_(True)
    f = fun(x)
    (g,) = torch.autograd.grad(f.sum(), x)
    return f.detach().nan_to_num(torch.inf, torch.inf, torch.inf), g.nan_to_num(0.0, 0.0, 0.0)


def _given(fun: Callable[[Tensor], tuple[Tensor, Tensor]], x: Tensor) -> tuple[Tensor, Tensor]:
    """:func:`_value_and_grad` for a ``fun`` that gives its gradient itself."""
    f, g = fun(x)
    return f.nan_to_num(torch.inf, torch.inf, torch.inf), g.nan_to_num(0.0, 0.0, 0.0)


def _rows_value_and_grad(
    fun: Callable[[Tensor, Tensor], Tensor], x: Tensor, idx: Tensor, gives_grad: bool = False
) -> tuple[Tensor, Tensor]:
    """Loss and gradient of the rows ``idx`` (R,) of x (B, D); inf and 0 elsewhere."""
    both = _given if gives_grad else _value_and_grad
    # (shape[0], not len(): Tensor.__len__ is Python code, a few microseconds a call)
    if idx.shape[0] == x.shape[0]:  # all rows: nothing to gather or scatter
        return both(lambda z: fun(z, idx), x)
    f = x.new_full(x.shape[:1], torch.inf)
    g = torch.zeros_like(x)
    if idx.shape[0]:
        f[idx], g[idx] = both(lambda z: fun(z, idx), x[idx])
    return f, g


class History:
    """The last ``m`` curvature pairs of every row, stacked for the compact form.

    The pairs live in a buffer (B, 2, L, D), s then y, with L = 2m slots: the window is the
    m slots before ``end``, oldest first, and a new pair goes to slot ``end``; when the
    buffer is full the newest m - 1 pairs move to its front (one copy every m + 1 pushes
    instead of a roll every push). The views of each window are made once and kept.

    A pair whose curvature fails the test (and a slot not filled yet) is stored as zeros:
    it then adds nothing to the compact form, exactly as the two-loop recursion skips a pair
    with rho = 0. scale (B, 1, 1): s.y / y.y of the newest valid pair in the window, 1 if
    there is none.
    """

    def __init__(self, x: Tensor, m: int) -> None:
        self.m, self.count, self.end = m, 0, m
        self.buf = x.new_zeros(x.shape[0], 2, 2 * m, x.shape[1])
        self.views: dict[int, tuple[Tensor, ...]] = {}
        # (B, 1, 1), like the pair's tests below, to scale (B, m | D, 1) with no view
        self.gamma = torch.ones_like(x[:, :1, None])  # s.y / y.y of the newest valid pair
        self.age = torch.full_like(self.gamma, m)  # pushes since it (m: none in the window)
        self.scale = self.gamma
        self.zero, self.one, self.limit = (x.new_tensor(c) for c in (0.0, 1.0, m))
        # a stand-in for s.y on the diagonal of R at the zero pairs (any positive number)
        self.tiny = x.new_tensor(torch.finfo(x.dtype).tiny)
        self.min_curvature = x.new_tensor(1e-10)

    def window(self) -> tuple[Tensor, ...]:
        """Views of the window: S, Y (B, m, D), S^T, Y^T (B, D, m); of its newest pair:
        (s, y) (B, 2, D), s and y (B, D), (s, y) (B, 2, 1, 1, D), s (B, 1, D), y (B, D, 1)."""
        views = self.views.get(self.end)
        if views is None:
            window = self.buf[:, :, self.end - self.m : self.end]
            s, y = window.unbind(1)
            new = window[:, :, -1]
            s_new, y_new = new.unbind(1)
            views = (s, y, s.mT, y.mT, new, s_new, y_new)
            views += (new[:, :, None, None], s_new[:, None], y_new[:, :, None])
            self.views[self.end] = views
        return views

    def push(self, x_new: Tensor, x: Tensor, g_new: Tensor, g: Tensor) -> Tensor:
        """Append (s, y) = (x_new - x, g_new - g), dropping the oldest; returns max |s| (B,)."""
        m, last = self.m, self.buf.shape[2]
        if self.end == last:
            self.buf[:, :, : m - 1] = self.buf[:, :, last - m + 1 :]
            self.end = m - 1
        self.end += 1
        self.count += 1
        new, s, y, new5, s_row, y_col = self.window()[4:]
        torch.sub(x_new, x, out=s)
        torch.sub(g_new, g, out=y)
        moved = torch.linalg.vector_norm(s, torch.inf, -1)
        s_norm, y_norm = torch.linalg.vector_norm(new5, dim=-1).unbind(1)  # (B, 1, 1)
        # s.y / y.y as (s.y / |y|) / |y|: y.y is never formed, so it cannot underflow to 0
        # for a tiny y (a zero y gives 0 / 0 = NaN, which fails the test below)
        sy_y = torch.bmm(s_row, y_col) / y_norm
        # a pair counts where its curvature is positive, relative to the step and gradient
        # change (s.y > 1e-10 |s| |y|; scale-free: a polish at losses of 1e-8 has both tiny)
        valid = sy_y > s_norm * self.min_curvature
        new.mul_(valid)
        self.gamma = torch.where(valid, sy_y / y_norm, self.gamma)
        self.age = torch.where(valid, self.zero, self.age + self.one)
        # the newest valid pair may have left the window: then there is none in it
        self.scale = torch.where(self.age < self.limit, self.gamma, self.one)
        return moved

    def direction(self, g: Tensor) -> Tensor:
        """-H g (B, D) for the gradient g (B, D), H the L-BFGS inverse Hessian of each row.

        Compact form (Byrd, Nocedal & Schnabel 1994), S, Y (B, m, D) the pairs, gamma the
        scale, R = triu(S Y^T), D = diag(S Y^T), u = R^-1 S g, q = g - Y^T u:
        H g = gamma q + S^T R^-T (D u - gamma Y q)  (Y q = Y g - Y Y^T u).
        A zero pair has zero rows and columns in S Y^T and zero entries in S g and Y q:
        with any positive number on R's diagonal there its u and R^-T(...) entries are 0, so
        it drops out.
        """
        if not self.count:
            return -g
        s, y, st, yt = self.window()[:4]
        g3 = g.unsqueeze(2)
        # the solves read R's upper triangle only (BLAS trsm): S Y^T needs no triu
        r = torch.bmm(s, yt)  # (B, m, m), contiguous
        m = self.m
        diag = r.as_strided((r.shape[0], m, 1), (m * m, m + 1, 1))  # (B, m, 1): one view
        diag.clamp_min_(self.tiny)
        u = torch.linalg.solve_triangular(r, torch.bmm(s, g3), upper=True)  # (B, m, 1)
        q = torch.baddbmm(g3, yt, u, alpha=-1)  # (B, D, 1)
        # D u: at the zero pairs the diagonal holds tiny instead of 0, but there u is 0
        v = torch.addcmul(diag * u, self.scale, torch.bmm(y, q), value=-1)
        p = torch.linalg.solve_triangular(r.mT, v, upper=False)
        return torch.baddbmm(q * self.scale, st, p, beta=-1, alpha=-1).squeeze(2)


def minimize(
    fun: Callable[..., Tensor],
    x0: Tensor,
    *,
    indexed: bool = False,
    gives_grad: bool = False,
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
    gives_grad: ``fun`` returns (loss, gradient (B, D)) itself, a closed form, instead of a
    loss that autograd differentiates.

    A row stops when its gradient is below ``tol_grad``, its loss below ``tol_loss``, an
    iteration changes its loss or its point by less than ``tol_change``, or (if ``tol_stall``
    > 0) its last ``stall_window`` iterations lowered its loss by less than the fraction
    ``tol_stall`` together, or ``max_failures`` line searches in a row end without a strong
    Wolfe point. The batch stops when no row is left.
    """

    def evaluate(x: Tensor, rows: Tensor) -> tuple[Tensor, Tensor]:
        """Loss and gradient at x; with ``indexed`` only the ``rows`` (R,) given."""
        if indexed:
            return _rows_value_and_grad(fun, x, rows, gives_grad)
        return _given(fun, x) if gives_grad else _value_and_grad(fun, x)

    def still(rows: Tensor) -> Tensor | None:
        """The rows (B,) that are True as an index (R,) (R x 1 unless ``indexed``), None if
        there are none: one ``nonzero`` is the host-side test, ``fun``'s index with
        ``indexed``, and tells whether all rows are in."""
        idx = rows.nonzero(as_tuple=True)[0] if indexed else rows.nonzero()
        return idx if idx.shape[0] else None

    x = x0.detach().clone()
    n = x.shape[0]
    f, g = evaluate(x, torch.arange(n, device=x.device))
    g = torch.where(torch.isinf(f)[:, None], 0.0, g)  # no gradient where there is no loss
    evals = 1
    active = (torch.linalg.vector_norm(g, torch.inf, -1) > tol_grad) & (f > tol_loss)
    hist = History(x, history)
    recent = [f]  # losses of the last stall_window iterations
    # 0-d constants: an operation with a Python number wraps it in a tensor every time
    minus_c2, zero, one = (x.new_tensor(c) for c in (-C2, 0.0, 1.0))
    # the line search's start: made once, as no operation below writes into them
    t_lr, lo0, hi0 = (torch.full_like(f, c) for c in (lr, 0.0, torch.inf))
    t_lr_col = t_lr[:, None]
    # the stopping tests as one comparison: max |g|, max |s|, loss change, loss and line
    # searches left before max_failures must exceed these (and, with tol_stall, the drop
    # over stall_window iterations tol_stall times the loss then)
    bound = x.new_tensor([tol_grad, tol_change, tol_change, tol_loss, 0.0, 0.0])[:, None]
    bounds = {5: bound[:5], 6: bound}
    stall = x.new_tensor(tol_stall)
    left = torch.full_like(f, max_failures)  # line searches that may still fail in a row
    limit = left.clone()
    it = 0
    for it in range(1, max_iter + 1):
        rows = still(active)
        if rows is None:
            break
        d = hist.direction(g)
        gtd = torch.linalg.vecdot(g, d)
        not_descent = gtd >= zero
        if not_descent.nonzero().shape[0]:  # restart those rows on steepest descent
            d = torch.where(not_descent[:, None], -g, d)
            gtd = torch.linalg.vecdot(g, d)
        if it == 1:
            t = lr * torch.clamp(1.0 / g.abs().sum(-1).clamp_min(1e-300), max=1.0)
            t_col = t[:, None]
        else:
            t, t_col = t_lr, t_lr_col
        wolfe_slope = gtd * minus_c2  # the strong Wolfe bound on |g.d| at the step
        lo, hi = lo0, hi0
        searching = active
        x_acc, f_acc, g_acc = x, f, g  # never written in place: no copies
        for _ in range(max_ls):
            x_try = torch.addcmul(x, t_col, d)
            if not indexed and rows.shape[0] < n:  # the others stay at their point
                x_try = torch.where(searching[:, None], x_try, x_acc)
            f_try, g_try = evaluate(x_try, rows)
            evals += 1
            armijo = f_try <= torch.addcmul(f, gtd, t, value=C1)
            slope = torch.linalg.vecdot(g_try, d)
            armijo_here = searching & armijo
            wolfe = armijo_here & (slope.abs() <= wolfe_slope)
            improve = armijo_here & (f_try < f_acc)
            up = improve[:, None]
            x_acc = torch.where(up, x_try, x_acc)
            f_acc = torch.where(improve, f_try, f_acc)
            g_acc = torch.where(up, g_try, g_acc)
            searching = searching ^ wolfe  # wolfe only where searching: those rows are done
            rows = still(searching)
            if rows is None:
                break
            # the rows that stopped searching never read t, lo, hi again: no masks
            shrink = ~armijo | (slope > zero)
            hi = torch.where(shrink, t, hi)
            lo = torch.where(shrink, lo, t)
            t = torch.where(torch.isinf(hi), t + t, torch.lerp(lo, hi, 0.5))
            t_col = t[:, None]
        # a search that ends without a Wolfe point failed; max_failures in a row stop the row
        left = torch.where(searching, left - one, limit)
        moved = hist.push(x_acc, x, g_acc, g)
        change = f - f_acc  # f_acc <= f: no abs (inf - inf is NaN, which fails the test too)
        x, f, g = x_acc, f_acc, g_acc
        tests = [torch.linalg.vector_norm(g, torch.inf, -1), moved, change, f, left]
        recent.append(f)
        if len(recent) > stall_window:
            old = recent.pop(0)
            if tol_stall > 0:  # (old - f) - tol_stall old > 0, i.e. (old - f) > tol_stall old
                tests.append(torch.addcmul(old - f, old, stall, value=-1))
        active = active & (torch.stack(tests) > bounds[len(tests)]).all(0)
    return LbfgsResult(x, f, it, evals)
