"""JKR contact of one power-law asperity: the closed forms and the stable-branch radius.

Any axisymmetric adhesive contact in the JKR limit is the adhesionless (Sneddon) contact of
radius a plus a flat punch of the same radius pulled back (Johnson 1985, sec. 5.5; Maugis
2000; Borodich, Galanov & Suarez-Alvarez 2014 for power laws). With kc = kappa(gamma) c
(``sneddon.log_kc``), w the work of adhesion in units of E* R (w_phys = w E* R), lengths in
units of R as everywhere in the core:

    delta(a) = kc a^gamma - sqrt(2 pi w R a)                                   [length]
    F(a) / E* = 2 gamma/(gamma + 1) kc a^(gamma + 1) - sqrt(8 pi w R a^3)      [length^2]

Three radii mark the curve, each a power of the one at zero indentation a0: the touch
radius a0, the detachment under displacement control a_d and the pull-off under load control
a_F (see ``physics.adhesion`` for the cell built from them). Every function is elementwise
and broadcasts over its tensor arguments; ``jkr_radius`` is differentiable (implicitly at
the root).
"""

from __future__ import annotations

import math

import numpy as np
import torch
from torch import Tensor

from metainterface.errors import MetainterfaceError
from metainterface.physics.sneddon import log_kc

#: Newton steps at most for a contact radius (they stop earlier once every step is below
#: round-off); from the starts below, loading points converge in 4-6.
NEWTON_STEPS = 60
#: Largest work of adhesion accepted, in units of E* R (a PDMS sphere of 1 um has ~0.02).
ADHESION_LIMIT = 1.0


def check_adhesion(w: object) -> float:
    """The work of adhesion as a float in [0, ADHESION_LIMIT] [E* R], or a one-line error."""
    if isinstance(w, bool | str) or w is None:
        raise MetainterfaceError(
            f"adhesion must be a number in [0, {ADHESION_LIMIT:g}] (E* R), got {w!r}",
            argument="adhesion",
        )
    try:
        value = float(w)  # type: ignore[arg-type]
    except (TypeError, ValueError):
        raise MetainterfaceError(
            f"adhesion must be a number in [0, {ADHESION_LIMIT:g}] (E* R), got {w!r}",
            argument="adhesion",
        ) from None
    if not (math.isfinite(value) and 0.0 <= value <= ADHESION_LIMIT):
        raise MetainterfaceError(
            f"adhesion must be in [0, {ADHESION_LIMIT:g}] (work of adhesion / E* R), got {value:g}",
            argument="adhesion",
        )
    return value


# --- one asperity, elementwise (any broadcastable shapes) ------------------------------------


def power_coefficient(gamma: Tensor, radius: float) -> Tensor:
    """kc = kappa(gamma) c: the Sneddon indentation coefficient, delta = kc a^gamma."""
    return torch.exp(log_kc(gamma, radius))


def flat_punch_coefficient(w: Tensor | float, radius: float) -> Tensor | float:
    """sqrt(2 pi w R): the flat punch's coefficient, delta_flat = sqrt(2 pi w R a)."""
    if isinstance(w, Tensor):
        return torch.sqrt(2.0 * math.pi * radius * w)
    return math.sqrt(2.0 * math.pi * radius * w)


def jkr_indentation(gamma: Tensor, a: Tensor, w: Tensor | float, radius: float = 1.0) -> Tensor:
    """delta(a) = kc a^gamma - sqrt(2 pi w R a) [length] at contact radius a >= 0 [length]."""
    kc = power_coefficient(gamma, radius)
    return kc * a**gamma - flat_punch_coefficient(w, radius) * torch.sqrt(a)


def jkr_force(
    gamma: Tensor,
    a: Tensor,
    w: Tensor | float,
    radius: float = 1.0,
    *,
    coefficient: Tensor | None = None,
) -> Tensor:
    """F / E* = 2 gamma/(gamma + 1) kc a^(gamma + 1) - sqrt(8 pi w R a^3) [length^2].
    coefficient: kc (``power_coefficient(gamma, radius)``) where the caller has it."""
    kc = power_coefficient(gamma, radius) if coefficient is None else coefficient
    hertz = 2.0 * gamma / (gamma + 1.0) * kc * a ** (gamma + 1.0)
    return hertz - 2.0 * flat_punch_coefficient(w, radius) * a * torch.sqrt(a)


def touch_radius(
    gamma: Tensor,
    w: Tensor | float,
    radius: float = 1.0,
    *,
    log_coefficient: Tensor | None = None,
) -> Tensor:
    """a0, the contact radius at zero indentation (snap-in at touch) [length]; 0 if w = 0.
    log_coefficient: log kc (``sneddon.log_kc(gamma, radius)``) where the caller has it."""
    w = torch.as_tensor(w, dtype=gamma.dtype, device=gamma.device)
    safe = torch.where(w > 0, w, torch.ones_like(w))
    lkc = log_kc(gamma, radius) if log_coefficient is None else log_coefficient
    log_a0 = (0.5 * torch.log(2.0 * math.pi * radius * safe) - lkc) / (gamma - 0.5)
    return torch.where(w > 0, torch.exp(log_a0), torch.zeros_like(log_a0))


def detach_radius(gamma: Tensor, w: Tensor | float, radius: float = 1.0) -> Tensor:
    """a_d = a0 (2 gamma)^(-1/(gamma - 1/2)): where d delta/da = 0, the least radius of the
    stable branch under displacement control [length]."""
    return touch_radius(gamma, w, radius) * (2.0 * gamma) ** (-1.0 / (gamma - 0.5))


def pull_off_radius(gamma: Tensor, w: Tensor | float, radius: float = 1.0) -> Tensor:
    """a_F = a0 (3 / (2 gamma))^(1/(gamma - 1/2)): where dF/da = 0, the radius at which one
    asperity comes off under load control [length]."""
    return touch_radius(gamma, w, radius) * (1.5 / gamma) ** (1.0 / (gamma - 0.5))


def jkr_radius(
    gamma: Tensor,
    x: Tensor,
    w: Tensor | float,
    radius: float = 1.0,
    *,
    self_coupling: Tensor | None = None,
    start: Tensor | None = None,
    log_coefficient: Tensor | None = None,
) -> Tensor:
    """Contact radius a [length] on the stable branch (a >= a_d) of delta(a) = x [length].

    Broadcasts over gamma, x, w. Where x < delta(a_d) there is no root: a_d is returned
    (the caller masks those asperities as detached). Newton's method without a graph, from
    a start right of a_d (delta is convex there, so after one step the iterates fall
    monotonically onto the root), then one step with a graph: the implicit gradient
    da/dtheta = -(d residual/dtheta) / (d residual/da), exact at the root.
    self_coupling: k (broadcastable), solves delta(a) + k F(a) / E* = x instead (an
    asperity's own images in the periodic lattice), |k| dF/da small against d delta/da.
    start: radii to start Newton from where they are on the stable branch (a root of a
    nearby x, e.g. the interaction's previous sweep); from the left of the root the first
    step lands right of it (convexity), so any start >= a_d converges.
    log_coefficient: log kc (``sneddon.log_kc(gamma, radius)``, with gamma's graph) where
    the caller has it (its lgamma is much of a call's cost; the result is the same).
    """
    w_t = torch.as_tensor(w, dtype=gamma.dtype, device=gamma.device)

    def residual(
        a: Tensor, g: Tensor, xx: Tensor, kc: Tensor, s: Tensor | float
    ) -> tuple[Tensor, Tensor]:
        root_a = torch.sqrt(a)
        pa = kc * a**g
        s_root = s * root_a
        res = pa - s_root - xx
        slope = (g * pa - 0.5 * s_root) / a
        if self_coupling is not None:
            f = (2.0 * g / (g + 1.0) * pa - 2.0 * s_root) * a
            df = 2.0 * g * pa - 3.0 * s_root
            res = res + self_coupling * f
            slope = slope + self_coupling * df
        return res, slope

    with torch.no_grad():
        g0, x0, w0 = gamma.detach(), x.detach(), w_t.detach()
        lk0 = log_kc(g0, radius) if log_coefficient is None else log_coefficient.detach()
        a_t = touch_radius(g0, w0, radius, log_coefficient=lk0)
        a_d = a_t * (2.0 * g0) ** (-1.0 / (g0 - 0.5))
        # the coefficients once, not at every Newton step (lgamma is most of a step's cost)
        kc = torch.exp(lk0)
        s = flat_punch_coefficient(w0, radius)
        # numpy's: torch.broadcast_shapes runs through torch._refs, whose first call imports
        # sympy and torch.fx (0.3 s of a design's start)
        shape = np.broadcast_shapes(a_t.shape, x0.shape, g0.shape)
        floor = torch.broadcast_to(a_d, shape)
        if start is not None:
            # where the start is off the branch (an asperity just in), a0: right of the root
            # for x < 0, left of it for x >= 0, where one step lands right of it
            a = torch.where(start.detach() > floor, start.detach(), a_t).expand(shape).clone()
        else:
            xp = torch.clamp_min(x0, 0.0)
            # a >= a_lo = max(Hertz radius, a0) for x >= 0; two fixed-point steps
            # a <- ((x + s sqrt(a)) / kc)^(1/gamma) from it stay below the root and near it
            hertz = (xp / kc) ** (1.0 / g0)
            a = torch.maximum(hertz, a_t)
            for _ in range(2):
                a = ((xp + s * torch.sqrt(a)) / kc) ** (1.0 / g0)
            # for x < 0 the root lies in [a_d, a0): start at a0, right of it
            a = torch.where(x0 >= 0, a, a_t)
            a = torch.broadcast_to(a, shape).clone()
        tiny = 4.0 * torch.finfo(a.dtype).eps
        for _ in range(NEWTON_STEPS):
            res, slope = residual(a, g0, x0, kc, s)
            ok = slope > 0
            step = torch.where(ok, res / torch.where(ok, slope, 1.0), 0.0)
            a_new = torch.maximum(a - step, floor)
            if bool(((a_new - a).abs() <= tiny * a).all()):
                a = a_new
                break
            a = a_new
    if not (gamma.requires_grad or x.requires_grad or w_t.requires_grad):
        return a
    kc = power_coefficient(gamma, radius) if log_coefficient is None else torch.exp(log_coefficient)
    res, slope = residual(a, gamma, x, kc, flat_punch_coefficient(w_t, radius))
    ok = slope.detach() > 0
    return a - torch.where(ok, res / torch.where(ok, slope.detach(), 1.0), 0.0)
