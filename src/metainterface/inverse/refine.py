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
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, replace

import numpy as np
import torch
from torch import Tensor

from metainterface.errors import MetainterfaceError
from metainterface.inverse import lbfgs, levmar
from metainterface.inverse.params import DTYPE, FULL, Parameterisation
from metainterface.inverse.perturb import Perturbation, loaded
from metainterface.physics.cell import CellSettings
from metainterface.physics.metrics import curve_error, interp_weights
from metainterface.physics.models import ForwardModel, get_model
from metainterface.physics.pressures import at_delta, at_delta_pullback, solve_delta
from metainterface.physics.tape import pullback

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


def _rows(target: TargetGrid, idx: Tensor) -> TargetGrid:
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


def _stage_value_and_grad(
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
        rows = _rows(target, idx)
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
            z, settings, _rows(target, idx), rs.undershoot_weight, model, param.rows(idx)
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
    :func:`robust_error`), all rows' copies in one batch, the same K draws throughout
    (common random numbers: a smooth objective). Returns the refined raw parameters."""
    rs = rs or RefineSettings()
    model = get_model(model)
    x = raw.detach().to(DTYPE)
    for kappa in rs.kappas():

        def fun(z: Tensor, idx: Tensor, kappa: float | None = kappa) -> Tensor:
            gamma, h = param.rows(idx).to_design(z, settings, sort=model.placed)
            rows = _rows(target, idx)
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
            closed = _stage_value_and_grad(
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
