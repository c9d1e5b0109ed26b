"""Single power-law asperity against an elastic half-space (Sneddon; paper sec. 2.1).

Profile f(r) = c r^gamma with c = 1 / (2 R^(gamma - 1)), so every shape has the base radius
R of a sphere (gamma = 2). With kc = kappa(gamma) c, an indentation delta gives

    contact radius  a = (delta / kc)^(1/gamma)
    force           F = E* 2 gamma / (gamma + 1) * delta * a
    area            A = pi a^2
    dF/ddelta       = 2 E* a
    dA/ddelta       = (2 / gamma) A / delta

All functions are pure, elementwise and broadcast over any leading shape. Lengths are in the
same unit as R (the core uses R = 1), forces in units of E* R^2.
"""

from __future__ import annotations

import math

import torch
from torch import Tensor
from torch.nn import functional as nnf


def log_kappa(gamma: Tensor) -> Tensor:
    """log kappa(gamma), kappa = sqrt(pi) Gamma(gamma/2 + 1) / Gamma((gamma + 1)/2), via lgamma."""
    return _lgamma_ratio(gamma) + 0.5 * math.log(math.pi)


def kappa(gamma: Tensor) -> Tensor:
    """kappa(gamma); equals pi/2, 2 and 3 pi/4 at gamma = 1, 2, 3."""
    return torch.exp(log_kappa(gamma))


def log_kc(gamma: Tensor, radius: float = 1.0) -> Tensor:
    """log(kappa(gamma) * c(gamma)) with c = 1 / (2 R^(gamma - 1)); shape of ``gamma``."""
    # the constants folded into one addition, the radius term only where R != 1: the
    # refinement computes this at every evaluation, where each operation costs ~5 us
    out = _lgamma_ratio(gamma) + (0.5 * math.log(math.pi) - math.log(2.0))
    return out if radius == 1.0 else out - (gamma - 1) * math.log(radius)


def dlog_kc(gamma: Tensor, radius: float = 1.0) -> Tensor:
    """d log(kappa c) / d gamma = psi(gamma/2 + 1)/2 - psi((gamma + 1)/2)/2 - log R."""
    half = 0.5 * gamma
    out = 0.5 * (torch.special.digamma(half + 1.0) - torch.special.digamma(half + 0.5))
    return out if radius == 1.0 else out - math.log(radius)


def _lgamma_ratio(gamma: Tensor) -> Tensor:
    """log Gamma(gamma/2 + 1) - log Gamma((gamma + 1)/2)."""
    half = 0.5 * gamma
    return torch.lgamma(half + 1.0) - torch.lgamma(half + 0.5)


def shape_constant(gamma: Tensor, radius: float = 1.0) -> Tensor:
    """c(gamma) = 1 / (2 R^(gamma - 1)) [R^(1 - gamma)]."""
    return 0.5 * radius ** (1 - gamma)


def indentation(gap: Tensor, smooth: float | None = None) -> Tensor:
    """Local compression from the gap Delta - h: Macaulay bracket, or softplus if ``smooth``.

    ``smooth`` is the softplus steepness kappa_s [1/length]: <x>_+ ~ log(1 + exp(kappa_s x)) /
    kappa_s, which tends to the exact bracket as kappa_s grows.
    """
    if smooth is None:
        return torch.clamp_min(gap, 0.0)
    return nnf.softplus(_tail(gap, smooth), beta=smooth, threshold=20.0)


def engagement(gap: Tensor, smooth: float | None = None) -> Tensor:
    """d(indentation)/d(gap): the step 1[gap > 0], or the logistic sigmoid if ``smooth``."""
    if smooth is None:
        return (gap > 0).to(gap.dtype)
    return torch.sigmoid(smooth * _tail(gap, smooth))


def _tail(gap: Tensor, smooth: float) -> Tensor:
    """The gap, floored at kappa_s gap = -60. Further out softplus and its sigmoid underflow
    to subnormal numbers, which slow every later operation on them ~100x on x86; the
    compression there (< 1e-26 / kappa_s) is below any contact threshold anyway."""
    return gap.clamp_min(-60.0 / smooth)


def contact_radius(gamma: Tensor, delta: Tensor, radius: float = 1.0) -> Tensor:
    """Contact radius a = (delta / (kappa c))^(1/gamma) [length]; 0 where delta <= 0.

    Finite value and finite gradients everywhere, including delta = 0 exactly.
    """
    positive = delta > 0
    safe = torch.where(positive, delta, torch.ones_like(delta))
    a = torch.exp((torch.log(safe) - log_kc(gamma, radius)) / gamma)
    return torch.where(positive, a, torch.zeros_like(a))


def force(gamma: Tensor, delta: Tensor, radius: float = 1.0, e_star: float = 1.0) -> Tensor:
    """Normal force F = E* 2 gamma/(gamma + 1) delta a [E* R^2 units when R = E* = 1]."""
    a = contact_radius(gamma, delta, radius)
    return e_star * 2 * gamma / (gamma + 1) * torch.clamp_min(delta, 0.0) * a


def area(gamma: Tensor, delta: Tensor, radius: float = 1.0) -> Tensor:
    """Real contact area A = pi a^2 [length^2]."""
    return math.pi * contact_radius(gamma, delta, radius) ** 2
