"""The composite loss of appendix A.2.

L = w_shape (|alpha_hat - t|_1 + |S_hat - t|_1) + w_grad |diff S_hat - diff t|_1
  + w_mag ((log10 P*_max - t)^2 + (log10 alpha_max - t)^2) + w_curve E + lambda L_param,
with L_param the MSE of (gamma - gamma_min)/(gamma_max - gamma_min) and h / Delta_max.
Norms are means over grid points and the batch. E, not in the paper (w_curve = 0 there), is
the batch mean of the relative curve error ||alpha - t||_2 / ||t||_2 on the target's own
pressure grid, the figure `evaluate` reports: shape and magnitude errors in one number.
"""

from __future__ import annotations

from dataclasses import dataclass

import torch
from torch import Tensor

from metainterface.physics.cell import CellSettings
from metainterface.physics.curves import Curve
from metainterface.physics.metrics import relative_l2
from metainterface.physics.pressures import alpha_at


@dataclass(frozen=True)
class LossWeights:
    """Weights of the composite training loss (paper appendix A.2): ``shape`` the L1 of
    alpha_hat and S_hat, ``grad`` the L1 of the S_hat differences, ``mag`` the squared log10
    errors of P*_max and alpha_max, ``curve`` the relative curve error. Dimensionless."""

    shape: float = 10.0
    grad: float = 1.0
    mag: float = 10.0
    curve: float = 0.0


PAPER_WEIGHTS = LossWeights()


def weights_of(model_config: dict) -> LossWeights:
    """The loss weights a model was trained with (its file's config; the paper's if absent)."""
    train = model_config.get("train", {})
    default = PAPER_WEIGHTS
    return LossWeights(
        shape=train.get("w_shape", default.shape),
        grad=train.get("w_grad", default.grad),
        mag=train.get("w_mag", default.mag),
        curve=train.get("w_curve", default.curve),
    )


@dataclass(frozen=True)
class CurveTargets:
    """Normalised target curves: alpha_hat, stiffness_hat (B, n); p_star_max, alpha_max (B,)."""

    alpha_hat: Tensor
    stiffness_hat: Tensor
    p_star_max: Tensor
    alpha_max: Tensor


def physics_loss(pred: Curve, target: CurveTargets, w: LossWeights = LossWeights()) -> Tensor:
    """Shape + magnitude loss of predicted curves against targets (a scalar)."""
    s_hat = pred.stiffness_hat
    shape = (pred.alpha_hat - target.alpha_hat).abs().mean() + (
        s_hat - target.stiffness_hat
    ).abs().mean()
    grad = (s_hat.diff(dim=-1) - target.stiffness_hat.diff(dim=-1)).abs().mean()
    mag = (
        (torch.log10(pred.p_star_max) - torch.log10(target.p_star_max)) ** 2
        + (torch.log10(pred.alpha_max) - torch.log10(target.alpha_max)) ** 2
    ).mean()
    loss = w.shape * shape + w.grad * grad + w.mag * mag
    if w.curve:
        loss = loss + w.curve * curve_error(pred, target).mean()
    return loss


def curve_error(pred: Curve, target: CurveTargets) -> Tensor:
    """(B,) relative L2 error of alpha on the target's pressure grid (held beyond P*_max).

    Both grids are uniform from 0, so the predicted curve is interpolated at fractional
    positions j P*_max,t / P*_max,pred of its own grid, without a search.
    """
    n = pred.n_steps
    ratio = target.p_star_max / pred.p_star_max
    pos = (pred.p_hat[None] * ((n - 1) * ratio)[:, None]).clamp(max=n - 1)
    left = pos.detach().floor().long().clamp(max=n - 2)
    frac = pos - left
    a0, a1 = pred.alpha.gather(-1, left), pred.alpha.gather(-1, left + 1)
    alpha = a0 + frac * (a1 - a0)
    return relative_l2(alpha, target.alpha_hat * target.alpha_max[:, None])


def param_loss(
    gamma: Tensor, h: Tensor, gamma_t: Tensor, h_t: Tensor, settings: CellSettings
) -> Tensor:
    """Normalised parameter MSE, the curriculum anchor (a scalar)."""
    span = settings.gamma_max - settings.gamma_min
    return torch.mean(((gamma - gamma_t) / span) ** 2) + torch.mean(
        ((h - h_t) / settings.delta_max) ** 2
    )


def law_error(gamma: Tensor, h: Tensor, target: CurveTargets, settings: CellSettings) -> Tensor:
    """(B,) relative L2 error of (B, N) designs' alpha at the target's own pressures.

    Exact contact law, alpha solved at each pressure (exact gradients; held beyond the
    design's reach): the zero-shot error `design` reports, on targets that may end far
    below Delta_max, where a uniform grid of the design's own range would hold few points.
    """
    n = target.alpha_hat.shape[-1]
    grid = torch.linspace(0, 1, n, dtype=gamma.dtype, device=gamma.device)
    p = grid[None] * target.p_star_max.to(gamma.dtype)[:, None]
    alpha, _ = alpha_at(gamma, h, settings, p, exact=True)
    return relative_l2(alpha, target.alpha_hat * target.alpha_max[:, None])
