"""Batched Levenberg-Marquardt for many independent small least-squares problems.

Each row b of the batch minimises ||r_b(x_b)||^2 over its own x_b (D,), with its own
damping lam: a step solves (J^T J + lam diag(J^T J)) dx = -J^T r (Marquardt's scaling, so
the damping does not depend on the parameters' units; by QR of the augmented system) and is
cut to ``max_step`` in max-norm. A step that lowers the loss is taken, one that does not is
refused, and lam follows the ratio of the actual to the predicted decrease (Nielsen's rule:
shrinks by up to 3 on a good step, doubles and doubles again on refusals). Near a zero
residual, which is where a realisable target is, the steps become Gauss-Newton ones, which
converge much faster than a quasi-Newton method there; each iteration costs one evaluation
of r and its Jacobian.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import torch
from torch import Tensor


@dataclass
class LsqResult:
    x: Tensor  # (B, D)
    loss: Tensor  # (B,) ||r||^2
    iterations: int
    evaluations: int


def least_squares(
    fun: Callable[[Tensor, Tensor], tuple[Tensor, Tensor]],
    x0: Tensor,
    *,
    max_iter: int = 50,
    tol_loss: float = 1e-12,
    tol_stall: float = 1e-4,
    stall_window: int = 5,
    damping: float = 1e-3,
    max_damping: float = 1e8,
    max_step: float = float("inf"),
) -> LsqResult:
    """Minimise ||r(x)||^2 row by row from x0 (B, D).

    fun(x, idx) -> (r (R, M), J (R, M, D)): the residuals of the rows ``idx`` (R,) of the
    batch at x (R, D) and their Jacobian; only the rows still running are evaluated. A
    non-finite loss counts as worse than any.

    A row stops when its loss is below ``tol_loss``, its last ``stall_window`` steps taken
    lowered it by less than the fraction ``tol_stall`` together, or its damping exceeds
    ``max_damping`` (~8 refusals in a row: no step that lowers the loss is left).
    """
    x = x0.detach().clone()
    b = x.shape[0]
    r, jac = fun(x, torch.arange(b, device=x.device))
    loss = _loss(r)
    evals = 1
    lam = torch.full_like(loss, damping)
    nu = torch.full_like(loss, 2.0)  # lam's factor at the next refusal
    active = loss > tol_loss
    # the losses after the last stall_window + 1 steps taken, oldest first
    taken = loss[:, None].repeat(1, stall_window + 1)
    count = torch.zeros_like(loss, dtype=torch.long)
    iterations = 0
    while iterations < max_iter:
        idx = active.nonzero(as_tuple=True)[0]
        if not idx.shape[0]:
            break
        iterations += 1
        j, res = jac[idx], r[idx]
        # The step solves [J; sqrt(lam D)] dx = [-r; 0] in the least-squares sense, D the
        # squared column norms of J (Marquardt's scaling), floored so that a parameter the
        # residuals ignore (a zero column) gets a finite, small step: by QR per row (LAPACK
        # gels; the damping makes the system full rank), better conditioned than the
        # normal equations. Zero rows pad the system to a multiple of 8 rows: LAPACK's
        # result depends on each matrix's memory alignment, and so, unpadded, on the row's
        # place in the batch (a batched matrix product depends on the batch's size too, and
        # gelsy on more), while a row's design must not depend on what else is in the batch.
        d = (j * j).sum(1)  # (R, D)
        floor = 1e-12 * d.amax(-1, keepdim=True) + torch.finfo(d.dtype).tiny
        damp = torch.diag_embed((lam[idx, None] * d.clamp_min(floor) + floor).sqrt())
        pad = torch.zeros_like(j[:, : -(j.shape[1] + j.shape[2]) % 8])
        aug = torch.cat([j, damp, pad], 1)  # (R, M + D + pad, D)
        rhs = torch.cat([-res, torch.zeros_like(aug[:, res.shape[1] :, 0])], 1)[..., None]
        step = torch.linalg.lstsq(aug, rhs, driver="gels").solution[..., 0]
        step = step.nan_to_num(0.0, 0.0, 0.0)
        if math.isfinite(max_step):
            longest = torch.linalg.vector_norm(step, torch.inf, -1, keepdim=True)
            step = step * (max_step / longest.clamp_min(max_step))
        x_try = x[idx] + step
        r_try, jac_try = fun(x_try, idx)
        evals += 1
        loss_try = _loss(r_try)
        old = loss[idx]
        better = loss_try < old
        predicted = old - _loss(res + (j * step[:, None, :]).sum(-1))
        gain = (old - loss_try) / predicted.clamp_min(torch.finfo(old.dtype).tiny)
        shrink = (1.0 - (2.0 * gain - 1.0) ** 3).clamp(1.0 / 3.0, 1.0)
        lam[idx] = torch.where(better, lam[idx] * shrink, lam[idx] * nu[idx])
        nu[idx] = torch.where(better, 2.0, nu[idx] * 2.0)
        took = idx[better]
        x[took], r[took], jac[took], loss[took] = (
            x_try[better],
            r_try[better],
            jac_try[better],
            loss_try[better],
        )
        taken[took] = torch.cat([taken[took, 1:], loss_try[better, None]], 1)
        count[took] += 1
        then = taken[:, 0]
        stalled = (count >= stall_window) & ((then - loss) <= tol_stall * then)
        active = active & (loss > tol_loss) & (lam <= max_damping) & ~stalled
    return LsqResult(x, loss, iterations, evals)


def _loss(r: Tensor) -> Tensor:
    """||r||^2 per row (B,), inf where not finite."""
    return (r * r).sum(-1).nan_to_num(torch.inf, torch.inf, torch.inf)
