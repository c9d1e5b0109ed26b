"""Choosing the forward model: the paper's independent asperities, or with elastic interaction.

One name per model, used by every command's ``--physics`` option:

    "independent"  curves.sweep: superposition of Sneddon contacts (paper sec. 2.2), default
    "interacting"  interaction.sweep_interacting: the same with the lattice's elastic field

Both have the signature of ``sweep`` and return a ``Sweep`` (delta (K,), P*, alpha, S* (B, K)).
"""

from __future__ import annotations

from typing import Protocol

import torch
from torch import Tensor

from metainterface.errors import MetainterfaceError
from metainterface.physics import curves
from metainterface.physics.cell import CellSettings, Design
from metainterface.physics.curves import Curve, Sweep, anchor, delta_grid, interp, sweep, to_grid
from metainterface.physics.interaction import (
    asperity_sweep_interacting,
    load_area_interacting,
    sweep_interacting,
)
from metainterface.physics.sneddon import area

PHYSICS: tuple[str, ...] = ("independent", "interacting")
DEFAULT_PHYSICS = "independent"


class SweepFunction(Protocol):
    def __call__(
        self,
        gamma: Tensor,
        h: Tensor,
        settings: CellSettings,
        *,
        smooth: float | None = None,
        n_delta: int | None = None,
        delta: Tensor | None = None,
    ) -> Sweep: ...


_SWEEPS: dict[str, SweepFunction] = {"independent": sweep, "interacting": sweep_interacting}


def check_physics(physics: str) -> str:
    """The model name, validated; MetainterfaceError naming the choices otherwise."""
    if physics not in _SWEEPS:
        raise MetainterfaceError(f"physics must be one of {', '.join(PHYSICS)}, got {physics!r}")
    return physics


def sweep_for(physics: str = DEFAULT_PHYSICS) -> SweepFunction:
    """The sweep function of a model: ``sweep_for("interacting")(gamma, h, settings, ...)``."""
    return _SWEEPS[check_physics(physics)]


def curve_for(
    gamma: Tensor,
    h: Tensor,
    settings: CellSettings,
    *,
    physics: str = DEFAULT_PHYSICS,
    smooth: float | None = None,
    n_delta: int | None = None,
) -> Curve:
    """``curves.curve`` with a choice of model: (B, N) designs -> alpha, S* on settings.n_steps."""
    sw = sweep_for(physics)(gamma, h, settings, smooth=smooth, n_delta=n_delta)
    return to_grid(sw, settings.n_steps)


def design_sweep_for(
    design: Design,
    *,
    physics: str = DEFAULT_PHYSICS,
    n_delta: int | None = None,
    smooth: float | None = None,
) -> Sweep:
    """The float64 sweep of one Design under a model: delta (K,), the rest (1, K)."""
    gamma, h = design.tensors(torch.float64)
    return sweep_for(physics)(gamma, h, design.settings, smooth=smooth, n_delta=n_delta)


def asperity_sweep(
    gamma: Tensor,
    h: Tensor,
    settings: CellSettings,
    *,
    physics: str = DEFAULT_PHYSICS,
    n_delta: int | None = None,
    delta: Tensor | None = None,
) -> tuple[Sweep, Tensor]:
    """The exact sweep of (B, N) designs and each asperity's contact area / A_nom, (B, K, N)."""
    if check_physics(physics) == "interacting":
        return asperity_sweep_interacting(gamma, h, settings, n_delta=n_delta, delta=delta)
    if delta is None:
        delta = delta_grid(settings, n_delta, dtype=gamma.dtype).to(gamma.device)
    sw = sweep(gamma, h, settings, delta=delta)
    gap = delta[None, :, None] - anchor(h)[:, None, :]
    return sw, area(gamma[:, None, :], gap, settings.radius) / settings.nominal_area


def alpha_at(
    gamma: Tensor,
    h: Tensor,
    settings: CellSettings,
    p_star: Tensor,
    *,
    physics: str = DEFAULT_PHYSICS,
    smooth: float | None = None,
    n_delta: int | None = None,
    exact: bool = False,
) -> tuple[Tensor, Tensor]:
    """``curves.alpha_at`` under a choice of model: alpha (B, M) at p_star (B, M), P*_max (B,).

    Same convention (alpha held at its last value beyond P*_max). Interpolated, the
    interacting model is run without its stiffness tangent, which alpha does not need (~25 %
    cheaper); ``exact`` (exact law only) solves P*(Delta) = p_star, which needs it.
    """
    fn = alpha_sweep_for(physics, exact)
    return curves.alpha_at(
        gamma, h, settings, p_star, smooth=smooth, n_delta=n_delta, sweep_fn=fn, exact=exact
    )


def alpha_sweep_for(physics: str = DEFAULT_PHYSICS, exact: bool = False) -> SweepFunction:
    """The sweep :func:`alpha_at` runs for a model: interpolated, the interacting one
    without its stiffness tangent; ``exact`` needs S* and dP*/dDelta."""
    if check_physics(physics) == "independent":
        return sweep
    return sweep_interacting if exact else _load_area_sweep


def _load_area_sweep(
    gamma: Tensor,
    h: Tensor,
    settings: CellSettings,
    *,
    smooth: float | None = None,
    n_delta: int | None = None,
    delta: Tensor | None = None,
) -> Sweep:
    """The interacting sweep without S* (its stiffness is NaN): for alpha(P*) only."""
    d, p, a = load_area_interacting(gamma, h, settings, smooth=smooth, n_delta=n_delta, delta=delta)
    return Sweep(delta=d, p_star=p, alpha=a, stiffness=torch.full_like(p, float("nan")))


def alpha_at_loads(
    gamma: Tensor,
    h: Tensor,
    settings: CellSettings,
    p_star: Tensor,
    *,
    physics: str = DEFAULT_PHYSICS,
    n_delta: int = 2049,
    max_extend: int = 6,
) -> Tensor:
    """alpha (B, Q) of (B, N) designs at the pressures p_star (B, Q): for comparing models.

    The models reach slightly different P* at Delta_max (the interacting one up to a few %
    more or less), so the exact sweep runs past Delta_max, doubling its range at most
    ``max_extend`` times, until it covers every requested P* (nothing is held constant).
    """
    interacting = check_physics(physics) == "interacting"
    top = p_star.max(dim=-1).values
    span = settings.delta_max
    for _ in range(max_extend + 1):
        delta = torch.linspace(0.0, span, n_delta, dtype=gamma.dtype, device=gamma.device)
        if interacting:
            _, p_sw, alpha = load_area_interacting(gamma, h, settings, delta=delta)
        else:
            sw = sweep(gamma, h, settings, delta=delta)
            p_sw, alpha = sw.p_star, sw.alpha
        if bool((p_sw[:, -1] >= top).all()):
            return interp(p_star, p_sw, alpha)
        span *= 2.0
    raise MetainterfaceError(
        f"P* up to {float(top.max()):.4g} is not reached by the {physics} model "
        f"within Delta <= {span / 2:.4g}"
    )
