"""The spread of made cells' errors: perturbed copies of designs, their curves and errors.

A made cell differs from its design: every asperity's height offset and shape exponent
carry independent Gaussian errors, and the relief as a whole may be scaled (a z-axis
calibration error or shrinkage). For a design (gamma, h) (N,) and standard normals
z = (z_gamma, z_h, z_s) of each sample, the made cell is

    gamma' = max(gamma + sigma_gamma z_gamma, GAMMA_FLOOR)   (clipped: gamma must stay > 1)
    h'     = (1 + scale_sigma z_s) h + sigma_h z_h            (then anchored, min h' -> 0)

with sigma_h in units of R. Heights are anchored by the forward model: Delta is counted
from the first contact of the made part, so only relative height errors matter. The scale
error scales the height offsets only; the tips' own shapes carry the gamma error.

Errors are the package's curve error (:func:`~metainterface.physics.metrics.curve_error`,
exact alpha at the reference's pressures), with one difference from ``design``'s: a made
cell that needs a deeper indentation than Delta_max to reach a pressure is loaded further
(up to ``REACH`` Delta_max) instead of having its alpha held at its last value, since
Delta_max bounds the design space, not the part.

All samples go through the batched forward model in one call; the first-order estimate
linearises alpha at the nominal design by autograd (one backward pass through a batch of
copies of the design, one per pressure) and pushes the same normals through it.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import torch
from torch import Tensor

from metainterface.inverse.losses import TargetGrid, relative_error
from metainterface.inverse.params import DTYPE
from metainterface.inverse.perturb import REACH, Perturbation, loaded
from metainterface.physics.cell import CellSettings
from metainterface.physics.metrics import curve_error
from metainterface.physics.models import ForwardModel

#: Bisection steps (in log sigma_h) of the radius search: the bracket [1e-6, 10] Delta_max,
#: a ratio of 1e7, shrinks to one of 1 + 1.5e-8, far below the Monte Carlo's own noise.
SEARCH_STEPS = 30
#: Normal quantile of the 5 % / 95 % band of the first-order estimate.
Z95 = 1.6448536269514722


@dataclass(frozen=True)
class Spread:
    """Curves and errors of S perturbed copies of one design (numpy, float64).

    p_star (M,) the band's pressures; alpha_nominal (M,); alpha (S, M) of the samples;
    errors (S,) relative curve errors to the reference; error_nominal: the nominal's.
    linear_sd (M,): first-order standard deviation of alpha; linear_errors (S,): the errors
    of the linearised model under the same normals; gamma, h (S, N): the sampled designs.
    """

    p_star: np.ndarray
    alpha_nominal: np.ndarray
    alpha: np.ndarray
    errors: np.ndarray
    error_nominal: float
    linear_sd: np.ndarray
    linear_errors: np.ndarray
    linear_rms: float
    gamma: np.ndarray
    h: np.ndarray
    clipped: float


def band_grid(gamma: Tensor, h: Tensor, settings: CellSettings, model: ForwardModel, points: int):
    """(points,) uniform pressures on [0, P*_max] of the (1, N) nominal design."""
    zero = torch.zeros(1, 1, dtype=DTYPE, device=gamma.device)
    with torch.no_grad():
        _, p_max = model.alpha_at(gamma, h, settings, zero, exact=True)
    return torch.linspace(0.0, 1.0, points, dtype=DTYPE, device=gamma.device) * p_max[0]


def reference_grid(
    gamma: Tensor,
    h: Tensor,
    settings: CellSettings,
    model: ForwardModel,
    target: tuple[np.ndarray, np.ndarray] | None,
    points: int,
) -> TargetGrid:
    """The curve the errors are measured to, on the grid ``design`` measures on: the
    target's (p_star, alpha) if given, else the nominal design's own curve."""
    if target is not None:
        return TargetGrid.from_curves([target], points).to(gamma.device)
    p = band_grid(gamma, h, settings, model, points)[None]
    with torch.no_grad():
        alpha, _ = model.alpha_at(gamma, h, settings, p, exact=True)
    return TargetGrid(p, alpha)


def spread(
    gamma: np.ndarray,
    h: np.ndarray,
    settings: CellSettings,
    model: ForwardModel,
    pert: Perturbation,
    *,
    target: tuple[np.ndarray, np.ndarray] | None = None,
    points: int = 128,
    linear: bool = True,
    device: torch.device | None = None,
) -> Spread:
    """Monte Carlo and first-order spread of one design (N,) under ``pert``.

    The band's pressures are ``points`` uniform ones on [0, P*_max] of the nominal design;
    the errors are :func:`~metainterface.inverse.losses.relative_error` on the reference's
    grid (the target's, or the nominal curve's). The nominal design and every sample are
    evaluated together: one batch of S + 1 rows at the band's and the reference's pressures,
    on ``device`` (default the CPU; ``pert``'s draws are moved there). numpy out.
    """
    dev = device or torch.device("cpu")
    g0 = torch.as_tensor(np.asarray(gamma), dtype=DTYPE, device=dev)[None]
    h0 = torch.as_tensor(np.asarray(h), dtype=DTYPE, device=dev)[None]
    pert = pert.to(dev)
    grid = band_grid(g0, h0, settings, model, points)
    ref = reference_grid(g0, h0, settings, model, target, points)
    own_settings, settings = settings, loaded(settings)
    m = grid.shape[0]
    p_all = torch.cat([grid, ref.p[0]])[None]
    g_s, h_s = pert.apply(g0, h0)
    # an adhesive curve's snap-ins are placed by its sweep's samples: the loaded range's
    # fall on the design's own ones and go on at their spacing (at the same count, a copy
    # identical to the design read up to 0.01 of alpha off it beside a snap-in)
    n_delta = round(REACH * (own_settings.n_steps - 1)) + 1 if model.adhesion else None
    with torch.no_grad():
        alpha, reach = model.alpha_at(
            torch.cat([g0, g_s]),
            torch.cat([h0, h_s]),
            settings,
            p_all.expand(g_s.shape[0] + 1, -1),
            exact=True,
            n_delta=n_delta,
        )
    band, at_ref = alpha[:, :m], alpha[:, m:]
    errors = curve_error(at_ref, ref.alpha.expand_as(at_ref), ref.p.expand_as(at_ref), reach)
    # the nominal error as design reports it: on the design's own Delta range (held at its
    # last value where it stops short), not loaded further like the made cells
    nominal = relative_error(g0, h0, own_settings, ref, model)
    out = dict(
        p_star=grid.cpu().numpy(),
        alpha_nominal=band[0].cpu().numpy(),
        alpha=band[1:].cpu().numpy(),
        errors=errors[1:].cpu().numpy(),
        error_nominal=float(nominal[0]),
        gamma=g_s.cpu().numpy(),
        h=h_s.cpu().numpy(),
        clipped=pert.clipped(g0),
    )
    if linear:
        jac = jacobian(g0, h0, settings, model, pert, p_all[0])  # (M_all, 2N + 1)
        lin = at_ref[0] - ref.alpha[0] + pert.z @ jac[m:].T  # (S, M_ref)
        norm = torch.linalg.vector_norm(ref.alpha[0])
        r0 = at_ref[0] - ref.alpha[0]
        out.update(
            linear_sd=torch.linalg.vector_norm(jac[:m], dim=-1).cpu().numpy(),
            linear_errors=(torch.linalg.vector_norm(lin, dim=-1) / norm).cpu().numpy(),
            linear_rms=float(torch.sqrt((r0**2).sum() + (jac[m:] ** 2).sum()) / norm),
        )
    else:
        nan = np.full(m, math.nan)
        out.update(
            linear_sd=nan, linear_errors=np.full(pert.samples, math.nan), linear_rms=math.nan
        )
    return Spread(**out)


def jacobian(
    gamma: Tensor,
    h: Tensor,
    settings: CellSettings,
    model: ForwardModel,
    pert: Perturbation,
    p_star: Tensor,
) -> Tensor:
    """d alpha(p_j) / d z_k at z = 0 for the (1, N) design: (M, 2N + 1), the Jacobian in
    the standard normals (so each column is scaled by its sigma).

    One row per pressure, each a copy of the design evaluated at that pressure only: one
    backward pass of the summed alphas gives every row (alpha at p_j depends on row j's
    copy alone). Exact law, at fixed pressure (the implicit derivative)."""
    m, n = p_star.shape[0], gamma.shape[-1]
    u = torch.zeros((m, 2 * n + 1), dtype=DTYPE, device=gamma.device, requires_grad=True)
    sig = pert.scales(n)
    z = u * sig
    g = gamma + z[:, :n]
    hh = h * (1.0 + z[:, 2 * n :]) + z[:, n : 2 * n]
    alpha, _ = model.alpha_at(g, hh, settings, p_star[:, None], exact=True)
    (jac,) = torch.autograd.grad(alpha.sum(), u)
    return jac.detach()


def p95(
    gamma: np.ndarray,
    h: np.ndarray,
    settings: CellSettings,
    model: ForwardModel,
    pert: Perturbation,
    *,
    target: tuple[np.ndarray, np.ndarray] | None = None,
    points: int = 128,
    device: torch.device | None = None,
) -> float:
    """The 95th percentile of the sampled relative errors (no band, no linearisation)."""
    s = spread(
        gamma, h, settings, model, pert, target=target, points=points, linear=False, device=device
    )
    return float(np.quantile(s.errors, 0.95))


def largest_sigma(
    gamma: np.ndarray,
    h: np.ndarray,
    settings: CellSettings,
    model: ForwardModel,
    pert: Perturbation,
    max_error: float,
    *,
    target: tuple[np.ndarray, np.ndarray] | None = None,
    iterations: int = 30,
    progress: Callable[[], object] | None = None,
    device: torch.device | None = None,
) -> tuple[float, float]:
    """The largest height error sigma_h [units of R] whose p95 error stays within
    ``max_error``, the other sigmas of ``pert`` kept; and the p95 error there.

    Bisection in log sigma_h over [1e-6, 10] Delta_max with the same normals at every probe
    (common random numbers: the p95 is then a smooth, increasing function of sigma_h, not
    a noisy one). Returns (0, p95 at sigma_h = 0) when even perfect heights miss the budget,
    and (inf, p95 at the top) when the top still meets it. ``progress`` is called after
    each probe (at most ``iterations`` + 3). Every probe runs on ``device`` (default the CPU).
    """
    pert = pert.to(device or torch.device("cpu"))  # moved once, not at every probe

    def probe(sigma: float) -> float:
        q = Perturbation(sigma, pert.sigma_gamma, pert.scale_sigma, pert.z)
        err = p95(gamma, h, settings, model, q, target=target, device=device)
        if progress is not None:
            progress()
        return err

    base = probe(0.0)
    if base > max_error:
        return 0.0, base
    lo, hi = 1e-6 * settings.delta_max, 10.0 * settings.delta_max
    top = probe(hi)
    if top <= max_error:
        return math.inf, top
    err_lo = probe(lo)
    if err_lo > max_error:
        return lo, err_lo
    for _ in range(iterations):
        mid = math.sqrt(lo * hi)
        err = probe(mid)
        if err <= max_error:
            lo, err_lo = mid, err
        else:
            hi = mid
    return lo, err_lo
