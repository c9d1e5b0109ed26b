"""A design at given pressures: alpha at a target's P* (the Delta sweep interpolated), and the
indentation Delta that makes each pressure (solved on the sweep, exact at the grid points)."""

from __future__ import annotations

import functools
from collections.abc import Callable
from dataclasses import replace

import torch
from torch import Tensor

from metainterface.physics.cell import CellSettings
from metainterface.physics.curves import Sweep, _contact_floor, anchor, delta_grid, sweep
from metainterface.physics.metrics import interp
from metainterface.physics.sneddon import log_kc
from metainterface.physics.tape import Pullback

#: Newton steps at most in :func:`at_pressures`, and its tolerance on |P*(Delta) - p| / p
#: (alpha then errs by ~1e-20 after the final step in alpha). From the interpolated start
#: 1-3 steps reach it: P*(Delta) of independent asperities is convex, so the iterates
#: approach the root from above after the first.
NEWTON_STEPS, NEWTON_TOL = 8, 1e-10


def alpha_at(
    gamma: Tensor,
    h: Tensor,
    settings: CellSettings,
    p_star: Tensor,
    *,
    smooth: float | None = None,
    n_delta: int | None = None,
    sweep_fn: Callable[..., Sweep] | None = None,
    exact: bool = False,
    load_fn: LoadFactory | None = None,
) -> tuple[Tensor, Tensor]:
    """alpha of (B, N) designs at given pressures p_star (B, M), and P*_max (B,).

    Beyond a design's P*_max its alpha is held at the last value (the convention of the
    relative curve error and of the refinement's undershoot term). ``sweep_fn`` picks the
    forward model (default: the independent one, :func:`sweep`). By default alpha is
    interpolated linearly in a sweep of ``n_delta`` samples (settings.n_steps); ``exact``
    solves P*(Delta) = p_star instead (:func:`at_pressures`, exact law only; ``sweep_fn``
    must give ``load_slope`` and S*) and is exact to round-off, with exact gradients;
    ``load_fn`` gives its Newton steps a cheaper load (see :func:`solve_delta`).
    """
    if exact:
        if smooth is not None:
            raise ValueError("exact alpha_at is for the exact contact law (smooth=None)")
        sw, p_max = at_pressures(
            gamma, h, settings, p_star, n_delta=n_delta, sweep_fn=sweep_fn, load_fn=load_fn
        )
        return sw.alpha, p_max
    sw = (sweep_fn or sweep)(gamma, h, settings, smooth=smooth, n_delta=n_delta)
    zero = torch.zeros_like(sw.p_star[:, :1])
    p = torch.cat([zero, sw.p_star], dim=-1)
    return interp(p_star, p, torch.cat([zero, sw.alpha], dim=-1)), p[:, -1]


#: ``load_fn(gamma, h, settings)`` -> ``load(delta=...)``: P* and dP*/dDelta (``load_slope``)
#: of (B, N) designs at per-design Deltas (B, M), for the Newton steps of :func:`solve_delta`
#: (a forward model's ``newton_load``).
LoadFactory = Callable[[Tensor, Tensor, CellSettings], Callable[..., Sweep]]


def independent_load(gamma: Tensor, h: Tensor, settings: CellSettings) -> Callable[..., Sweep]:
    """``load(delta=...)``: P* and dP*/dDelta of the independent model of (B, N) designs at
    per-design Deltas (B, M), nothing else.

    The Newton steps of :func:`at_pressures` need only these: ~12 tensor operations a call
    without a graph (the per-asperity constants are computed once, here), where
    :func:`sweep` takes ~35 and keeps its products for a backward. alpha and S* are left
    zeros and are not to be used.
    """
    h = anchor(h)[:, :, None]
    floor = _contact_floor(gamma.dtype)
    inv_g = (1.0 / gamma)[:, :, None]
    lkc = log_kc(gamma, settings.radius)[:, :, None]
    f_coef = (2.0 * gamma / (gamma + 1.0))[:, :, None]
    a_nom = settings.nominal_area

    def load(*, delta: Tensor, **_: object) -> Sweep:
        d = torch.relu(delta[:, None, :] - h)  # (B, N, M)
        a = torch.exp(inv_g * (torch.log(d.clamp_min(floor)) - lkc))
        a = a * (d > floor)
        p_star = (f_coef * d * a).sum(1) / a_nom
        zeros = torch.zeros_like(p_star)
        # dF/dd = 2 a for a power-law contact (the Sneddon force's slope)
        return Sweep(delta, p_star, zeros, zeros, load_slope=(2.0 / a_nom) * a.sum(1))

    return load


def at_pressures(
    gamma: Tensor,
    h: Tensor,
    settings: CellSettings,
    p_star: Tensor,
    *,
    n_delta: int | None = None,
    sweep_fn: Callable[..., Sweep] | None = None,
    load_fn: LoadFactory | None = None,
) -> tuple[Sweep, Tensor]:
    """The exact-law response of (B, N) designs where P*(Delta) equals p_star (B, M), and
    P*_max (B,) (detached); Delta = Delta_max where p_star >= P*_max.

    Delta is solved for without gradients (:func:`solve_delta`), then one sweep with
    gradients at that Delta (:func:`at_delta`): P* and S* there carry gradients in gamma and
    h at fixed Delta, and alpha is alpha(p_star) with its gradient at fixed pressure.
    ``sweep_fn`` (default :func:`sweep`) must accept a (B, M) ``delta`` and give
    ``load_slope``.
    """
    delta, p_max = solve_delta(
        gamma, h, settings, p_star, n_delta=n_delta, sweep_fn=sweep_fn, load_fn=load_fn
    )
    return at_delta(gamma, h, settings, p_star, delta, p_max, sweep_fn=sweep_fn), p_max


def solve_delta(
    gamma: Tensor,
    h: Tensor,
    settings: CellSettings,
    p_star: Tensor,
    *,
    n_delta: int | None = None,
    sweep_fn: Callable[..., Sweep] | None = None,
    load_fn: LoadFactory | None = None,
) -> tuple[Tensor, Tensor]:
    """Delta (B, M) where P*(Delta) = p_star (B, M) for (B, N) designs, Delta_max where
    p_star >= P*_max; and P*_max (B,). No gradients.

    Newton steps from the linear interpolation of an ``n_delta``-sample sweep, kept inside
    the sweep's bracket of the root (P* grows with Delta). The steps evaluate ``load_fn``'s
    load (a forward model's ``newton_load``), else, for the default ``sweep_fn``, only P* and
    its slope (:func:`independent_load`), else the whole sweep.
    """
    fn = sweep_fn or sweep
    with torch.no_grad():
        if load_fn is not None:
            newton_fn = load_fn(gamma, h, settings)
        elif fn is sweep:
            newton_fn = independent_load(gamma, h, settings)
        else:
            newton_fn = functools.partial(fn, gamma, h, settings)
        knots_fn = getattr(newton_fn, "knots", None)
        if knots_fn is not None:  # an adhesive path: no snap-in inside a bracket
            grid = knots_fn(n_delta)
        else:
            grid = delta_grid(settings, n_delta, dtype=gamma.dtype, device=gamma.device)
            grid = grid.expand(gamma.shape[0], -1)
        coarse = newton_fn(delta=grid)
        knots = coarse.delta.expand(gamma.shape[0], -1)
        p_max = coarse.p_star[:, -1]
        beyond = p_star >= p_max[:, None]
        delta = interp(p_star, coarse.p_star, knots)
        if knots_fn is not None:
            # the knots around the first crossing of the running maximum: the rising force
            # reaches p_star there, and no touch lies between them
            k = torch.searchsorted(coarse.p_star.contiguous(), p_star.contiguous())
            k = k.clamp(1, knots.shape[-1] - 1)
            lo, hi = knots.gather(-1, k - 1), knots.gather(-1, k)
            delta = torch.minimum(torch.maximum(delta, lo), hi)
        else:
            step = float(knots[0, 1] - knots[0, 0])
            lo = (delta - step).clamp_min(0.0)
            hi = (delta + step).clamp_max(settings.delta_max)
        tol = max(NEWTON_TOL, 64 * torch.finfo(p_star.dtype).eps) * p_star.abs()
        # round-off of a force summed to P*_max is the floor (a zero load read just above
        # the snap-in plateau, 1e-12 of the top load, cannot be met to 1e-10 of itself)
        tol = torch.maximum(tol, 64 * torch.finfo(p_star.dtype).eps * p_max[:, None])
        for _ in range(NEWTON_STEPS):
            sw = newton_fn(delta=delta)
            if sw.load_slope is None:
                raise ValueError("at_pressures needs a sweep_fn that gives load_slope")
            resid = torch.where(beyond, 0.0, sw.p_star - p_star)
            # converged points stay put: each point's Delta, and so a design's result, does
            # not depend on the other rows of the batch
            done = resid.abs() <= tol
            if bool(done.all()):
                break
            slope = sw.load_slope
            newton = ~done & (slope > 0)
            move = torch.where(newton, resid / torch.where(slope > 0, slope, 1.0), 0.0)
            # a point short of its load where the curve is flat (an adhesive cell inside a
            # snap-in, where the force has not yet regained its running maximum) has no
            # Newton step: it moves up, halfway to the top of its bracket, which the sweep's
            # knots put past the root
            stuck = ~done & ~newton & (resid < 0)
            lo = torch.where(stuck, delta, lo)
            delta = torch.where(
                stuck, 0.5 * (delta + hi), torch.minimum(torch.maximum(delta - move, lo), hi)
            )
    return delta, p_max


def at_delta(
    gamma: Tensor,
    h: Tensor,
    settings: CellSettings,
    p_star: Tensor,
    delta: Tensor,
    p_max: Tensor,
    *,
    sweep_fn: Callable[..., Sweep] | None = None,
) -> Sweep:
    """The response of (B, N) designs at the Deltas (B, M) that :func:`solve_delta` found
    for p_star (B, M), with alpha moved to p_star; P*_max (B,) as it gave.

    One Newton step in alpha at the converged, detached Delta: its value is alpha(p) to
    second order in the residual, and its gradient is the implicit one, d alpha/d theta at
    fixed p = partial alpha/partial theta - (1/S*) partial P*/partial theta.
    """
    sw = (sweep_fn or sweep)(gamma, h, settings, delta=delta)
    return replace(sw, alpha=_step(sw, p_star, inverse_stiffness(sw, p_star, p_max)))


def at_delta_pullback(
    sweep_fn: Callable[..., tuple[Sweep, Pullback]],
    gamma: Tensor,
    h: Tensor,
    p_star: Tensor,
    delta: Tensor,
    p_max: Tensor,
) -> tuple[Tensor, Callable[[Tensor], tuple[Tensor, Tensor]]]:
    """alpha (B, M) of :func:`at_delta` by a model's closed-form sweep (its
    ``load_area_pullback``), and the pullback ``back(g_alpha)`` -> the gradients (B, N) of
    gamma and h for upstream gradients (B, M) of alpha: the same gradient, with no graph."""
    sw, back = sweep_fn(gamma, h, delta=delta)
    inv_s = inverse_stiffness(sw, p_star, p_max)
    return _step(sw, p_star, inv_s), lambda g: back(-g * inv_s, g)


def _step(sw: Sweep, p_star: Tensor, inv_s: Tensor) -> Tensor:
    """The Newton step in alpha from the sweep's state to p_star (B, M)."""
    return sw.alpha + (p_star - sw.p_star) * inv_s


def inverse_stiffness(sw: Sweep, p_star: Tensor, p_max: Tensor) -> Tensor:
    """1/S* (B, M) of :func:`at_delta`'s step in alpha, detached: d alpha at fixed p is
    d alpha - (1/S*) d P* at fixed Delta. 0 where S* is not positive or p_star >= P*_max
    (B,) (alpha is held there)."""
    ok = (sw.stiffness > 0) & (p_star < p_max[:, None])
    return torch.where(ok, 1.0 / torch.where(ok, sw.stiffness, 1.0), 0.0).detach()
