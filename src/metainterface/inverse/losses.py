"""The refinement's losses on a target's pressure grid (paper appendix C): the masked
weighted MSE of the softplus stages (alpha interpolated in a sweep) and of the exact law,
its residuals and their Jacobian for the Levenberg-Marquardt polish, the same loss with its
gradient by hand where the model has a closed form (``physics.tape``), and the curve errors
that rank designs. The optimisers that minimise them are in :mod:`~metainterface.inverse.refine`.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, replace

import numpy as np
import torch
from torch import Tensor

from metainterface.inverse.params import DTYPE, FULL, Parameterisation
from metainterface.inverse.perturb import Perturbation, loaded
from metainterface.physics.cell import CellSettings
from metainterface.physics.metrics import curve_error, interp_weights
from metainterface.physics.models import ForwardModel
from metainterface.physics.pressures import at_delta, at_delta_pullback, solve_delta
from metainterface.physics.registry import get_model
from metainterface.physics.tape import pullback


@dataclass(frozen=True)
class TargetGrid:
    """Targets on their own uniform pressure grids: p, alpha (T, G); weight (T, G), each
    point's weight in the loss relative to the others (None: all 1)."""

    p: Tensor
    alpha: Tensor
    weight: Tensor | None = None

    @classmethod
    def from_curves(cls, curves: list[tuple[np.ndarray, np.ndarray]], points: int) -> TargetGrid:
        ps, alphas = [], []
        for p, a in curves:
            grid = np.linspace(0.0, float(p[-1]), points)
            ps.append(grid)
            alphas.append(np.interp(grid, p, a, left=0.0))
        return cls(
            torch.tensor(np.array(ps), dtype=DTYPE), torch.tensor(np.array(alphas), dtype=DTYPE)
        )

    def rows(self, index: Tensor) -> TargetGrid:
        weight = None if self.weight is None else self.weight[index]
        return TargetGrid(self.p[index], self.alpha[index], weight)

    def to(self, device: torch.device) -> TargetGrid:
        """The grid on ``device``."""
        weight = None if self.weight is None else self.weight.to(device)
        return TargetGrid(self.p.to(device), self.alpha.to(device), weight)


def rows_of(target: TargetGrid, idx: Tensor) -> TargetGrid:
    """The rows ``idx`` (R,) of ``target``, ascending as the optimisers give them: the grid
    itself when they are all of its rows (two gathers fewer per evaluation)."""
    return target if idx.shape[0] == target.p.shape[0] else target.rows(idx)


def masked_loss(
    gamma: Tensor,
    h: Tensor,
    settings: CellSettings,
    target: TargetGrid,
    smooth: float | None,
    undershoot: float = 0.1,
    model: ForwardModel | None = None,
) -> Tensor:
    """The weighted MSE of appendix C per row (B,), relative to mean(alpha_t^2).

    With the softplus (the stages) alpha is interpolated in the paper's 128-sample sweep;
    on the exact law (the polish) it is exact at the target's pressures, as in
    :func:`relative_error`."""
    model = get_model(model)
    if smooth is not None:
        sw = model.load_area(gamma, h, settings, smooth=smooth)
        p = model.loads_read(target.p)  # an adhesive sweep's zero load: its plateau's end
        return InterpolatedLoss.apply(
            sw.p_star, sw.alpha, p, target.alpha, undershoot, target.weight
        )
    alpha, p_max = model.alpha_at(gamma, h, settings, target.p, exact=True)
    return (point_weights(p_max, target, undershoot) * (alpha - target.alpha) ** 2).sum(-1)


def point_weights(p_max: Tensor, target: TargetGrid, undershoot: float = 0.1) -> Tensor:
    """Each target point's weight in :func:`masked_loss` (B, M): 1 where the design's curve
    reaches it (p <= P*_max (B,)), ``undershoot`` beyond, times the grid's own weight if it
    has one, over sum(weights) mean(alpha_t^2)."""
    w = torch.where(target.p <= p_max[:, None], 1.0, undershoot)
    if target.weight is not None:
        w = w * target.weight
    return w / (w.sum(-1, keepdim=True) * (target.alpha**2).mean(-1, keepdim=True))


class InterpolatedLoss(torch.autograd.Function):
    """(P*, alpha) of a sweep (B, K) -> :func:`masked_loss` (B,), alpha interpolated at the
    target's pressures in the sweep with a (0, 0) knot first, held beyond its end.

    The stages evaluate this ~300 times per design; autograd through the interpolation and
    the weighted MSE took ~45 operations for the backward, the closed form below ~20:
    with dL/dalpha_q = 2 weight (alpha_q - alpha_t), alpha_q = (1 - w) f0 + w f1 and
    w = (p - x0) / (x1 - x0), dalpha_q/dx0 = (w - 1) s and dalpha_q/dx1 = -w s, s the
    interval's slope (only where w is not clamped); the weights' step at P*_max has no
    gradient.
    """

    @staticmethod
    def forward(ctx, p_sweep, alpha_sweep, p, alpha_t, undershoot, weight=None):
        zero = torch.zeros_like(p_sweep[:, :1])
        xp, fp = torch.cat([zero, p_sweep], -1), torch.cat([zero, alpha_sweep], -1)
        idx, w, width, ratio = interp_weights(p, xp)
        f0 = fp.gather(-1, idx - 1)
        rise = fp.gather(-1, idx) - f0
        diff = f0 + w * rise - alpha_t
        weights = point_weights(xp[:, -1], TargetGrid(p, alpha_t, weight), undershoot)
        inside = (width > 0) & (ratio >= 0) & (ratio <= 1)  # where w is not clamped
        slope = torch.where(inside, rise / torch.where(inside, width, 1.0), 0.0)
        ctx.save_for_backward(idx, w, slope, weights * diff)
        ctx.knots = xp.shape[-1]
        return (weights * diff * diff).sum(-1)

    @staticmethod
    def backward(ctx, g):
        idx, w, slope, wdiff = ctx.saved_tensors
        ga = (2.0 * g)[:, None] * wdiff  # dL/dalpha_q (B, M)
        both = torch.cat([idx - 1, idx], -1)
        grad_f = ga.new_zeros(ga.shape[0], ctx.knots)
        grad_f.scatter_add_(-1, both, torch.cat([ga - ga * w, ga * w], -1))
        gs = ga * slope
        grad_x = ga.new_zeros(ga.shape[0], ctx.knots)
        grad_x.scatter_add_(-1, both, torch.cat([gs * w - gs, -gs * w], -1))
        return grad_x[:, 1:], grad_f[:, 1:], None, None, None, None


def stage_value_and_grad(
    model: ForwardModel,
    param: Parameterisation,
    settings: CellSettings,
    target: TargetGrid,
    smooth: float | None,
    undershoot: float,
) -> Callable[[Tensor, Tensor], tuple[Tensor, Tensor]] | None:
    """A stage's :func:`masked_loss` with its gradient in the unbounded parameters, the
    chain of closed-form pullbacks applied by hand (``physics.tape``): ``fun(z, idx)`` ->
    (loss (R,), gradient (R, D)) for the rows ``idx``. None where a step has no closed form
    (a model without one, a placed model's sort): autograd then."""
    sweep_fn = model.load_area_pullback(settings, smooth)
    if sweep_fn is None or model.placed:
        return None
    needs = (True, True, False, False, False, False)

    def fun(z: Tensor, idx: Tensor) -> tuple[Tensor, Tensor]:
        rows = rows_of(target, idx)
        gamma, h, back_param = param.rows(idx).to_design_pullback(z, settings)
        if smooth is None:  # the exact law: alpha at the target's pressures, as alpha_at
            with torch.no_grad():
                delta, p_max = solve_delta(
                    gamma, h, settings, rows.p, sweep_fn=model.sweep, load_fn=model.newton_load
                )
            alpha, back = at_delta_pullback(sweep_fn, gamma, h, rows.p, delta, p_max)
            weights, diff = point_weights(p_max, rows, undershoot), alpha - rows.alpha
            loss = (weights * diff**2).sum(-1)
            return loss, back_param(*back(2.0 * weights * diff))
        sw, back_sweep = sweep_fn(gamma, h)
        args = (sw.p_star, sw.alpha, rows.p, rows.alpha, undershoot, rows.weight)
        loss, back_loss = pullback(InterpolatedLoss, needs, *args)
        g_p, g_alpha = back_loss(torch.ones_like(loss))[:2]
        return loss, back_param(*back_sweep(g_p, g_alpha))

    return fun


def residuals(
    raw: Tensor,
    settings: CellSettings,
    target: TargetGrid,
    undershoot: float = 0.1,
    model: ForwardModel | None = None,
    param: Parameterisation = FULL,
) -> tuple[Tensor, Tensor]:
    """The exact-law loss as residuals r (B, M), ||r||^2 = :func:`masked_loss`, and their
    Jacobian in the unbounded parameters, dr/draw (B, M, D).

    Each point's alpha depends on the parameters only through the design at its own Delta
    (solved once, without gradients), so the batch is replicated once per point, (B M) rows
    at one Delta each, and one backward pass of the summed alphas gives every row of J: the
    cost of one gradient evaluation, not M.
    """
    model = get_model(model)
    # an adhesive model reads zero load where the force holds it, as alpha_at and the
    # reported error do (the plateau P* = 0 of a snap-in reads less area)
    target = replace(target, p=model.loads_read(target.p))
    b, m = target.p.shape
    fn = model.sweep
    with torch.no_grad():
        gamma, h = param.to_design(raw, settings, sort=model.placed)
        delta, p_max = solve_delta(
            gamma, h, settings, target.p, sweep_fn=fn, load_fn=model.newton_load
        )
        weight = point_weights(p_max, target, undershoot).sqrt()  # (B, M)
    rep = raw.detach().repeat_interleave(m, 0)
    closed = model.load_area_pullback(settings)
    if closed is not None and not model.placed:  # the same Jacobian with no graph
        g_rep, h_rep, back_param = param.to_design_pullback(rep, settings)
        p_rep, d_rep, p_max_rep = (
            target.p.reshape(-1, 1),
            delta.reshape(-1, 1),
            p_max.repeat_interleave(m),
        )
        alpha, back = at_delta_pullback(closed, g_rep, h_rep, p_rep, d_rep, p_max_rep)
        jac = back_param(*back(torch.ones_like(alpha)))
        r = weight * (alpha.view(b, m) - target.alpha)
        return r, weight[..., None] * jac.view(b, m, -1)
    rep.requires_grad_(True)
    g_rep, h_rep = param.to_design(rep, settings, sort=model.placed)
    alpha = at_delta(
        g_rep,
        h_rep,
        settings,
        target.p.reshape(-1, 1),
        delta.reshape(-1, 1),
        p_max.repeat_interleave(m),
        sweep_fn=fn,
    ).alpha
    (jac,) = torch.autograd.grad(alpha.sum(), rep)
    r = weight * (alpha.detach().view(b, m) - target.alpha)
    return r, weight[..., None] * jac.view(b, m, -1)


def relative_error(
    gamma: Tensor,
    h: Tensor,
    settings: CellSettings,
    target: TargetGrid,
    model: ForwardModel | None = None,
) -> Tensor:
    """The package's curve error (:func:`~metainterface.physics.metrics.curve_error`) on the
    target's grid: the relative L2 error where the design reaches (exact law, alpha exact
    at the target's pressures), combined with the share of the load range it misses. (B,)."""
    with torch.no_grad():
        alpha, p_max = get_model(model).alpha_at(gamma, h, settings, target.p, exact=True)
        return curve_error(alpha, target.alpha, target.p, p_max)


def robust_error(
    gamma: Tensor,
    h: Tensor,
    settings: CellSettings,
    target: TargetGrid,
    perturb: Perturbation,
    model: ForwardModel | None = None,
) -> Tensor:
    """The robust design's objective as an error (B,): sqrt((e_0^2 + mean_k e_k^2) / 2),
    e_0 the design's own :func:`relative_error` and e_k its K perturbed copies'.

    The made copies are loaded past Delta_max where they need it (:func:`loaded`); the
    nominal term, on the design's own Delta range as ``design`` measures it, keeps a design
    whose own range stops short of the target from winning on copies that reach it only
    that way (in the loss its points beyond its reach count in full, not at the
    undershoot weight)."""
    k = perturb.samples
    g_k, h_k = perturb.apply(gamma, h)
    rows = target.rows(torch.arange(gamma.shape[0], device=gamma.device).repeat_interleave(k))
    made = relative_error(g_k, h_k, loaded(settings), rows, model).view(-1, k)
    nominal = relative_error(gamma, h, settings, target, model)
    return (0.5 * (nominal**2 + made.pow(2).mean(-1))).sqrt()
