"""Material limits: the peak contact pressure of power-law asperities (paper end of sec. 4.1).

With the equivalent (MDR) profile g(x) = kappa c x^gamma of an asperity f(r) = c r^gamma and
contact radius a, the pressure under it is

    p(r) = (E* / pi) int_r^a g'(x) / sqrt(x^2 - r^2) dx = E* gamma kappa c a^(gamma-1) I(r/a) / pi,
    I(t) = int_t^1 s^(gamma-1) / sqrt(s^2 - t^2) ds
         = sqrt(1 - t^2) 2F1(1 - gamma/2, 1; 3/2; 1 - t^2).

At the centre I(0) = 1 / (gamma - 1) (Hertz, gamma = 2: p0 = 2 E* a / (pi R)). For gamma <= 2
the pressure is largest at the centre; for gamma > 2 it is not: the maximum sits at
t* = r*/a in (0, 1) (gamma = 4: I = (1 + 2 t^2) sqrt(1 - t^2) / 3, largest at t* = 1/sqrt 2).

How it is computed (torch has no 2F1): with s = t cosh u,
I(t) = int_0^acosh(1/t) (t cosh u)^(gamma-1) du, a smooth integrand on a finite range,
integrated by 64-point Gauss-Legendre (relative error ~1e-9 or better for gamma in (1, 20] and
t in (0, 1), checked against direct adaptive quadrature). t*(gamma) is found once by a
vectorised golden-section search and tabulated on a uniform gamma grid (32 points per unit);
at run time t* is interpolated (no gradient is needed there: dI/dt = 0 at the maximum) and
I(t*) is evaluated by the quadrature, so the peak is smooth and differentiable in gamma and in
the indentation (relative error of max_t I below 1e-6).
Using kappa c a^(gamma-1) = (kappa c)^(1/gamma) delta^(1 - 1/gamma):

    p_max / E* = gamma (kappa c)^(1/gamma) delta^(1 - 1/gamma) max_t I(t) / pi.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass
from typing import Any

import numpy as np
import torch
from torch import Tensor

from metainterface.errors import MetainterfaceError
from metainterface.physics.cell import CellSettings, Design
from metainterface.physics.curves import anchor
from metainterface.physics.sneddon import indentation, log_kc

_QUAD_NODES = 64
_TABLE_PER_UNIT = 32  # gamma grid points per unit of gamma in the t* table
_GOLDEN_STEPS = 48


@functools.lru_cache(maxsize=4)
def _gauss_legendre(n: int) -> tuple[np.ndarray, np.ndarray]:
    """Nodes and weights of n-point Gauss-Legendre on [0, 1]."""
    x, w = np.polynomial.legendre.leggauss(n)
    return 0.5 * (x + 1.0), 0.5 * w


def pressure_shape(gamma: Tensor, t: Tensor) -> Tensor:
    """I(t) = int_t^1 s^(gamma-1) / sqrt(s^2 - t^2) ds, broadcast over gamma and t.

    gamma > 1 (dimensionless); t = r / a in [0, 1]. The pressure profile is
    p(r) = E* gamma kappa c a^(gamma-1) I(r/a) / pi; I(0) = 1/(gamma - 1), I(1) = 0.
    """
    gamma, t = torch.broadcast_tensors(gamma, t)
    x_np, w_np = _gauss_legendre(_QUAD_NODES)
    x = torch.as_tensor(x_np, dtype=gamma.dtype, device=gamma.device)
    w = torch.as_tensor(w_np, dtype=gamma.dtype, device=gamma.device)
    inside = (t > 0) & (t < 1)
    ts = torch.where(inside, t, torch.full_like(t, 0.5))
    upper = torch.acosh(1.0 / ts)  # u range [0, acosh(1/t)]
    s = ts[..., None] * torch.cosh(upper[..., None] * x)  # (..., Q), s in [t, 1]
    integral = upper * (w * s.pow(gamma[..., None] - 1.0)).sum(-1)
    centre = 1.0 / (gamma - 1.0)
    return torch.where(inside, integral, torch.where(t <= 0, centre, torch.zeros_like(t)))


@functools.lru_cache(maxsize=8)
def _peak_table(gamma_hi: int) -> tuple[np.ndarray, np.ndarray]:
    """(gamma grid on [2, gamma_hi], t* at each point), by golden-section search (float64)."""
    gammas = torch.linspace(2.0, float(gamma_hi), _TABLE_PER_UNIT * (gamma_hi - 2) + 1)
    gammas = gammas.to(torch.float64)
    lo = torch.zeros_like(gammas)
    hi = torch.ones_like(gammas)
    ratio = (math.sqrt(5.0) - 1.0) / 2.0
    with torch.no_grad():
        for _ in range(_GOLDEN_STEPS):  # I is unimodal in t; keep the bracket of its maximum
            t1 = hi - ratio * (hi - lo)
            t2 = lo + ratio * (hi - lo)
            left = pressure_shape(gammas, t1) > pressure_shape(gammas, t2)
            hi = torch.where(left, t2, hi)
            lo = torch.where(left, lo, t1)
    t_star = 0.5 * (lo + hi)
    t_star[0] = 0.0  # gamma = 2: the centre
    return gammas.numpy(), t_star.numpy()


def peak_location(gamma: Tensor) -> Tensor:
    """t* = r*/a where the pressure under a power-law asperity peaks; 0 for gamma <= 2.

    gamma: any shape, > 1. No gradient flows through t* (dI/dt vanishes there).
    """
    g = gamma.detach()
    gamma_hi = max(8, math.ceil(float(g.max())) + 1) if g.numel() else 8
    grid_np, t_np = _peak_table(gamma_hi)
    grid = torch.as_tensor(grid_np, dtype=g.dtype, device=g.device)
    table = torch.as_tensor(t_np, dtype=g.dtype, device=g.device)
    pos = ((g - 2.0) * _TABLE_PER_UNIT).clamp(0.0, grid.numel() - 1.0)
    i0 = pos.floor().long().clamp(max=grid.numel() - 2)
    frac = pos - i0
    t = table[i0] + frac * (table[i0 + 1] - table[i0])
    return torch.where(g > 2.0, t, torch.zeros_like(t))


def peak_factor(gamma: Tensor) -> Tensor:
    """max over t of I(t): 1/(gamma - 1) for gamma <= 2, I(t*) above. Differentiable in gamma."""
    return pressure_shape(gamma, peak_location(gamma))


def peak_pressure(gamma: Tensor, delta: Tensor, radius: float = 1.0, e_star: float = 1.0) -> Tensor:
    """Largest contact pressure under a power-law asperity at indentation delta [E* units].

    gamma, delta: broadcast (e.g. (B, N)); delta in units of R; 0 where delta <= 0.
    p_max = E* gamma (kappa c)^(1/gamma) delta^(1 - 1/gamma) max_t I(t) / pi; Hertz (gamma = 2):
    2 E* a / (pi R). Finite value and gradients everywhere, delta = 0 included.
    """
    gamma, delta = torch.broadcast_tensors(gamma, delta)
    positive = delta > 0
    safe = torch.where(positive, delta, torch.ones_like(delta))
    scale = torch.exp(log_kc(gamma, radius) / gamma + (1.0 - 1.0 / gamma) * torch.log(safe))
    p = e_star * gamma * scale * peak_factor(gamma) / math.pi
    return torch.where(positive, p, torch.zeros_like(p))


def asperity_peak_pressures(
    gamma: Tensor,
    h: Tensor,
    settings: CellSettings,
    *,
    delta: float | None = None,
    smooth: float | None = None,
) -> Tensor:
    """(B, N) peak pressure p/E* of each asperity at global indentation delta.

    gamma, h: (B, N) shape exponents and height offsets [units of R], heights anchored as in
    the forward model (min h -> 0). delta: global indentation [units of R], default
    Delta_max (the largest load). smooth: softplus steepness, None for the exact bracket.
    """
    d_global = settings.delta_max if delta is None else float(delta)
    local = indentation(d_global - anchor(h), smooth)
    return peak_pressure(gamma, local, settings.radius, 1.0)


def pressure_penalty(
    gamma: Tensor,
    h: Tensor,
    settings: CellSettings,
    limit: float,
    *,
    smooth: float | None = None,
) -> Tensor:
    """(B,) differentiable penalty mean_i relu(p_i / limit - 1)^2 at Delta_max.

    limit: the largest allowed p/E* (> 0). Zero when every asperity stays below the limit;
    a design-refinement loss adds ``weight * pressure_penalty(...)``.
    """
    if not (math.isfinite(limit) and limit > 0):
        raise MetainterfaceError(f"pressure limit p/E* must be > 0, got {limit!r}")
    p = asperity_peak_pressures(gamma, h, settings, smooth=smooth)
    return torch.relu(p / limit - 1.0).square().mean(-1)


@dataclass(frozen=True)
class PressureCheck:
    """Peak pressures of one design at Delta_max against a limit.

    peak: (N,) p/E* of each asperity; location: (N,) r*/a where it peaks; limit: p/E*.
    e_star: E* [Pa] when known (the report then also gives stresses in Pa).
    """

    peak: np.ndarray
    location: np.ndarray
    limit: float
    e_star: float | None = None

    @property
    def exceeds(self) -> np.ndarray:
        """(N,) bool: asperities whose peak pressure is above the limit (would yield)."""
        return self.peak > self.limit

    @property
    def failing(self) -> list[int]:
        """Indices k of the asperities above the limit."""
        return [int(k) for k in np.flatnonzero(self.exceeds)]

    @property
    def ok(self) -> bool:
        return not bool(self.exceeds.any())

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready report (p/E*, and Pa if E* is known)."""
        out: dict[str, Any] = {
            "limit_p_over_e_star": self.limit,
            "peak_p_over_e_star": [float(v) for v in self.peak],
            "peak_r_over_a": [float(v) for v in self.location],
            "exceeding": self.failing,
            "ok": self.ok,
        }
        if self.e_star is not None:
            out["limit_pa"] = self.limit * self.e_star
            out["peak_pa"] = [float(v * self.e_star) for v in self.peak]
        return out

    def summary(self) -> str:
        """One line for the terminal."""
        worst = int(np.argmax(self.peak))
        head = (
            f"peak contact pressure p/E* = {self.peak[worst]:.4g} (asperity {worst}), "
            f"limit {self.limit:.4g}"
        )
        if self.ok:
            return head + ": all asperities below the limit"
        return head + f": asperities {self.failing} would yield"


def check_pressure(design: Design, limit: float, *, e_star: float | None = None) -> PressureCheck:
    """Compare each asperity's peak pressure at Delta_max with a limit.

    limit: p/E* if ``e_star`` is None, else a stress [Pa] divided by e_star = E* [Pa].
    """
    if not (math.isfinite(limit) and limit > 0):
        raise MetainterfaceError(f"pressure limit must be > 0, got {limit!r}")
    if e_star is not None and not (math.isfinite(e_star) and e_star > 0):
        raise MetainterfaceError(f"modulus E* must be > 0, got {e_star!r}")
    ratio = limit if e_star is None else limit / e_star
    gamma, h = design.tensors(torch.float64)
    with torch.no_grad():
        peak = asperity_peak_pressures(gamma, h, design.settings)[0]
        where = peak_location(gamma[0])
    return PressureCheck(peak=peak.numpy(), location=where.numpy(), limit=ratio, e_star=e_star)
