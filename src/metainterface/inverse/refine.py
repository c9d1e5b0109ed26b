"""Multi-stage L-BFGS refinement of designs against targets (paper appendix C).

Parameters are unbounded: gamma = gamma_min + (gamma_max - gamma_min) sigmoid(r_gamma), and
heights h = [0, Delta_max softplus(r_h)] (the Delta_max factor keeps r_h of order one; the
first asperity is the anchor at h = 0), re-sorted at every evaluation with each gamma kept with
its h. The loss is the masked weighted MSE on the target's pressure grid: weight 1 where the
design's curve exists, 0.1 where it stops short of the target's largest pressure (its alpha
held at the last value there), nothing beyond the target; it is divided by mean(alpha_t^2)
so that tolerances do not depend on the target's scale. Stages: kappa_s log-spaced from
kappa_start to kappa_end, each stage ``steps_per_stage`` L-BFGS steps of ``iterations``
iterations (5 x 5 x 20, learning rate 0.5, strong Wolfe, by default) at most. A row stops
early when its loss stalls (``tol_stall``) or its line search fails three times running;
stopped rows are no longer evaluated, so many starts cost little more than the few slowest.
The losses themselves are in :mod:`~metainterface.inverse.losses`.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, replace

import numpy as np
import torch
from torch import Tensor

from metainterface.errors import MetainterfaceError
from metainterface.inverse import lbfgs, levmar
from metainterface.inverse.losses import (
    TargetGrid,
    masked_loss,
    residuals,
    rows_of,
    stage_value_and_grad,
)
from metainterface.inverse.params import DTYPE, FULL, Parameterisation
from metainterface.inverse.perturb import Perturbation, loaded
from metainterface.physics.cell import CellSettings
from metainterface.physics.models import ForwardModel
from metainterface.physics.registry import get_model

POLISH_METHODS = ("levmar", "lbfgs")

#: The hedge starts run only for targets whose refined zero-shot design misses them by more
#: than this relative curve error (the robust one when designing for it): a design already
#: within it gains nothing that matters from more starts (half the BEM's own accuracy,
#: verify.correct.STOP_ERROR, at which a BEM check stops correcting), and the hedges cost
#: several times the design (1e-4 before: no better on realisable targets, and several
#: times slower on the README's; benchmarks/results/design_speed.md).
HEDGE_ERROR = 5e-4


@dataclass(frozen=True)
class RefineSettings:
    """The refinement's stages, iterations and tolerances (paper appendix C; the comments in
    the source give the why of each).

    ``stages`` softplus stages with kappa_s log-spaced from ``kappa_start`` to ``kappa_end``
    [1/R], each ``steps_per_stage`` L-BFGS steps of at most ``iterations`` iterations at
    learning rate ``lr``; the loss on ``grid_points`` uniform pressures, with weight
    ``undershoot_weight`` where a design's curve stops short of the target. Then the best rows
    get up to ``polish_iterations`` more by ``polish_method`` ("levmar" or "lbfgs") on the
    exact contact law. Fewer stages or iterations make a quicker, rougher design.
    """

    stages: int = 5
    steps_per_stage: int = 5
    iterations: int = 20
    lr: float = 0.5
    kappa_start: float = 1e3
    kappa_end: float = 1e5
    undershoot_weight: float = 0.1
    grid_points: int = 128
    # A row leaves a stage once 5 iterations lower its loss by less than this fraction:
    # far fewer evaluations at the same final errors (benchmarks/bench_design.py).
    tol_stall: float = 0.01
    # then the winning row of each target gets up to this many more iterations (``polish``),
    # on the exact contact law (``polish_exact``) or at kappa_end, stopping only once 5
    # iterations lower the loss by less than ``polish_tol_stall`` together: rows still
    # converging run on, a row in a local minimum (the linear law's) stops
    polish_iterations: int = 100
    polish_tol_stall: float = 1e-4
    polish_exact: bool = True
    # The polish's method on the exact law: "levmar", Levenberg-Marquardt on the loss's
    # residuals (:func:`residuals`; their Jacobian costs one gradient), steps cut to
    # ``polish_max_step`` in the unbounded parameters; or "lbfgs", more iterations of the
    # stages' method. The exact law's loss has kinks and curved valleys that Gauss-Newton
    # steps follow and quasi-Newton pairs do not (bench_design.py --polish compares them).
    polish_method: str = "levmar"
    polish_max_step: float = 0.3
    # the stages use the exact contact law instead of the softplus (set by ``polishing``)
    exact: bool = False
    # L-BFGS stops a row whose gradient (max abs) or loss change falls below these; the
    # polish turns both off, since a loss of 1e-8 (an error of 0.01 %) is a good design,
    # not a converged one
    tol_grad: float = 1e-7
    tol_change: float = 1e-10
    # A row that meets its target to this relative curve error has met it and stops: far
    # below the BEM's accuracy. Errors of this order rank nothing: the exact law's loss has
    # kinks where asperities engage, and where a refinement stops there moves with the last
    # bits of the start.
    tol_error: float = 1e-5
    # Designs with asperities idle over the target's range get re-seeded starts
    # (``inverse.reseed``), as costly as the design itself; a scale search's quick candidates
    # skip them (they rank scales; the chosen one is designed in full, re-seed included)
    reseed: bool = True
    # and an adhesive offset law's design a last polish with its F_0 weighted
    # (``inverse.offset``), which the quick candidates skip too
    offset: bool = True

    def __post_init__(self) -> None:
        if self.polish_method not in POLISH_METHODS:
            raise MetainterfaceError(
                f"polish_method must be one of {', '.join(POLISH_METHODS)}, "
                f"got {self.polish_method!r}"
            )

    def polishing(self) -> RefineSettings:
        """The settings of the polish: up to ``polish_iterations`` more iterations with the
        finer stall test ``polish_tol_stall``, the last stretch that the stages' early stops
        skip, run on the designs kept.

        On the exact law by default: the error is measured on it, and the softplus shifts
        each engagement by ~ln 2 / kappa_s, which leaves a floor of ~0.1-0.2 % on targets
        that a design meets exactly (the built-in bilinear)."""
        return replace(
            self,
            stages=1,
            kappa_start=self.kappa_end,
            steps_per_stage=1,
            iterations=self.polish_iterations,
            tol_stall=self.polish_tol_stall,
            exact=self.polish_exact,
            tol_grad=0.0,
            tol_change=0.0,
        )

    def kappas(self) -> list[float | None]:
        """The contact law of each stage: softplus steepness, None for the exact law."""
        if self.exact:
            return [None] * self.stages
        return np.logspace(
            np.log10(self.kappa_start), np.log10(self.kappa_end), self.stages
        ).tolist()


def polish(
    raw: Tensor,
    settings: CellSettings,
    target: TargetGrid,
    rs: RefineSettings | None = None,
    param: Parameterisation = FULL,
    extra_loss: Callable[[Tensor, Tensor, CellSettings], Tensor] | None = None,
    model: ForwardModel | None = None,
    perturb: Perturbation | None = None,
) -> Tensor:
    """The polish after the stages: Levenberg-Marquardt on the exact law if
    ``rs.polish_method`` says so and the loss is a sum of squares (no ``extra_loss``, no
    ``perturb``), then L-BFGS (``RefineSettings.polishing``) on the rows it left above the
    design tolerance; else L-BFGS alone. Returns the polished raw parameters (B, D)."""
    rs = rs or RefineSettings()
    lm = rs.polish_method == "levmar" and rs.polish_exact
    if not lm or extra_loss is not None or perturb is not None:
        return refine(raw, settings, target, rs.polishing(), param, extra_loss, model, perturb)
    model = get_model(model)

    def fun(z: Tensor, idx: Tensor) -> tuple[Tensor, Tensor]:
        return residuals(
            z, settings, rows_of(target, idx), rs.undershoot_weight, model, param.rows(idx)
        )

    res = levmar.least_squares(
        fun,
        raw.detach().to(DTYPE),
        max_iter=rs.polish_iterations,
        tol_loss=rs.tol_error**2,
        tol_stall=rs.polish_tol_stall,
        max_step=rs.polish_max_step,
    )
    # A target point just past an asperity's engagement (alpha ~ (Delta - h)^(2/gamma), an
    # infinite slope) makes the linear model wrong at any step size, and Levenberg-Marquardt
    # can stall there, where L-BFGS's line search steps over the kink. The rows it left above
    # the design tolerance also get the L-BFGS polish from the same start, and keep the
    # better of the two (a row in a local minimum, the linear law's, stops both at once).
    x = res.x
    left = (res.loss > rs.tol_error**2).nonzero(as_tuple=True)[0]
    if left.shape[0]:
        rows = target.rows(left)
        sub = param.rows(left)
        y = refine(raw[left], settings, rows, rs.polishing(), sub, None, model)
        with torch.no_grad():
            loss = masked_loss(
                *sub.to_design(y, settings, sort=model.placed),
                settings,
                rows,
                None,
                rs.undershoot_weight,
                model,
            )
        better = loss < res.loss[left]
        x[left] = torch.where(better[:, None], y, x[left])
    return x


def refine(
    raw: Tensor,
    settings: CellSettings,
    target: TargetGrid,
    rs: RefineSettings | None = None,
    param: Parameterisation = FULL,
    extra_loss: Callable[[Tensor, Tensor, CellSettings], Tensor] | None = None,
    model: ForwardModel | None = None,
    perturb: Perturbation | None = None,
) -> Tensor:
    """Run the stages on a batch of unbounded parameters (B, D); each row is its own problem
    against the matching row of ``target``. ``extra_loss(gamma, h, settings) -> (B,)`` is
    added if given (e.g. a pressure limit). With ``perturb`` (robust design) a row's loss is
    the mean of the design's loss and the mean loss of its K perturbed copies (see
    :func:`~metainterface.inverse.losses.robust_error`), all rows' copies in one batch, the
    same K draws throughout (common random numbers: a smooth objective). Returns the refined
    raw parameters."""
    rs = rs or RefineSettings()
    model = get_model(model)
    x = raw.detach().to(DTYPE)
    for kappa in rs.kappas():

        def fun(z: Tensor, idx: Tensor, kappa: float | None = kappa) -> Tensor:
            gamma, h = param.rows(idx).to_design(z, settings, sort=model.placed)
            rows = rows_of(target, idx)
            if perturb is None:
                loss = masked_loss(gamma, h, settings, rows, kappa, rs.undershoot_weight, model)
            else:
                # the nominal's points beyond its reach count in full (see robust_error)
                loss = masked_loss(gamma, h, settings, rows, kappa, 1.0, model)
                k = perturb.samples
                g_k, h_k = perturb.apply(gamma, h)
                rows = rows.rows(torch.arange(len(idx), device=idx.device).repeat_interleave(k))
                wide = loaded(settings)  # made cells load past Delta_max where they need it
                made = masked_loss(g_k, h_k, wide, rows, kappa, rs.undershoot_weight, model)
                loss = 0.5 * (loss + made.view(-1, k).mean(-1))
            return loss if extra_loss is None else loss + extra_loss(gamma, h, settings)

        closed = None
        if perturb is None and extra_loss is None:
            closed = stage_value_and_grad(
                model, param, settings, target, kappa, rs.undershoot_weight
            )
        x = lbfgs.minimize(
            closed or fun,
            x,
            indexed=True,
            gives_grad=closed is not None,
            lr=rs.lr,
            max_iter=rs.steps_per_stage * rs.iterations,
            tol_stall=rs.tol_stall,
            tol_grad=rs.tol_grad,
            tol_change=rs.tol_change,
            tol_loss=rs.tol_error**2,
        ).x
    return x
