"""Adhesive periodic contact with the boundary element method, in torch (issue 38).

The same half-space as ``torch_bem`` (E* = 1, periodic, the Fourier kernel
u_hat = 2 p_hat / (E* |q|) and its inverse p_hat = E* |q| u_hat / 2, zero mean mode), a
rigid surface z (tips up) held at a prescribed mean gap g_bar (displacement control: an
adhesive contact has unstable branches under load control, which a path of mean gaps
follows). Gap g = u - z - c >= 0; the mean pressure P* is an output. Two adhesion laws:

Maugis-Dugdale, a resolved range (Rey, Anciaux & Molinari, Comput. Mech. 60, 2017, 69-81).
A cohesive zone pulls with sigma_0 = w / rho wherever 0 < g < rho, nothing beyond: the
interface energy is phi(g) = -w (1 - g / rho) for g < rho, 0 beyond. The gap is the primal
unknown: the total energy E(g) = 1/2 <u, K^-1 u> + sum phi(g), u = g + z, is minimised
over g >= 0 at fixed mean gap by a projected conjugate gradient on the points out of
contact, its gradient q = K^-1 u + phi'(g) (Polonsky & Keer's scheme with the roles of
pressure and gap exchanged): a step, a projection onto g >= 0, points in contact whose
gradient asks to open put back out, a rescaling to the mean gap. On the free points q is
the constant -P* at convergence; the pressure is p = K^-1 u + P*. Where the range spans
several grid points this is the Tabor-regime contact (JKR when rho is small against the
contact, DMT when large): checked against Tamaas's ``MaugisAdhesionFunctional``.

JKR, the range unresolved (Pohrt & Popov, Facta Univ. Mech. Eng. 13, 2015, 3-10). At a
sharp (JKR) edge the tension is -K_I / sqrt(2 pi s) at distance s from it, with K_I =
sqrt(2 E* w) when the energy released equals w. A grid of spacing dx cannot follow that;
the stress of the edge element is instead c_e K_I / sqrt(dx), c_e a constant of the
discretisation. The mesh-dependent criterion: a point in contact comes off where its
tension exceeds sigma_c = c_e sqrt(2 E* w / dx), and a point comes into contact where the
surfaces overlap, or, beside the contact, where the gap is below the opening of a critical
crack half a spacing behind its edge, c_g sqrt(2 E* w dx) / E*, c_g = 2 / sqrt(pi) from the
crack's opening profile (so the edge sits where the energy released equals w on loading
too: the reversible JKR branch that the forward model follows; a point that came off in a
solve closes again only by overlap, so the updates cannot cycle). At each mean gap the
bonded problem (g = 0 on the contact set C, p = 0 off it) is linear and solved by conjugate
gradients on the points of C, preconditioned with the half-space's stiffness E* |q| / 2
kept to C (as ``torch_bem``), each set warm-started from the last set's pressures; C is
updated by the two rules until it no longer changes, and the state returned has its
displacement (and so its residual) computed afresh. The transforms along the rows run on
the rows that hold a point of C only, and the preconditioner's in float32 (the residual the
solve is held to is float64's; ``benchmarks/bench_adhesive_bound.py`` measures the cost, in
benchmarks/results/adhesion.md). c_e (``EDGE_FACTOR``) is calibrated for this kernel on a
flat punch (it comes off at Kendall's F = sqrt(8 pi w E* a^3)), see
``adhesive_edge.pull_off_factor``, and c_g follows from the crack's opening; the JKR sphere
is then an independent check: a Hertz asperity's contact fraction against the JKR a(P) at
each compressive force, loading and unloading, falls with the grid (the edge is placed to a
fraction of a spacing; benchmarks/results/adhesion.md) up to about 256 points per cell side.
Past that it does not: both thresholds are pixel-scale constants, an edge pinned between
them sits within a share of K_c that the grid does not shrink, and a rising force's edge
lags JKR's at low loads (``benchmarks/bench_adhesive_convergence.py``;
``adhesive_path.FINEST`` caps the check's and validation's grids there).

Everything is float64 (but the JKR preconditioner, above) and batched over a leading axis
B of cells of one grid size and side (``heights`` (B, M, M)); no loops over grid points.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import torch
from torch import Tensor

from metainterface.errors import MetainterfaceError
from metainterface.validation.torch_bem import displacement, unit_kernel

#: The edge-element factor c_e of the JKR (Pohrt-Popov) criterion for this kernel: a bonded
#: flat punch pulled through ``solve_jkr`` comes off at Kendall's force with it
#: (``adhesive_edge.pull_off_factor``: 1.016-1.027, mean 1.021, over six sub-pixel radii
#: a / dx = 20-32 at 256^2, the resolution of a check; it rises slowly with a / dx, 1.006 at
#: 6-12, 1.011 at 10-25). It was 1.035, the most tensile point of the untrimmed disc
#: (``adhesive_edge.edge_factor``): the first point to come off, after which the trimmed edge
#: holds a few % more, so a receding edge lagged (a Hertz asperity's unloading read +3.35 %
#: at 256^2).
EDGE_FACTOR = 1.021
#: The closing factor c_g, from the JKR crack's opening: at a sharp edge of stress intensity K
#: the gap a distance s outside it is sqrt(8 / pi) K sqrt(s) / E* (Kendall's flat punch,
#: the first term of arcsin near the edge). A point beside the contact closes when its gap
#: is below that opening at s = dx / 2 with K = K_c = sqrt(2 E* w), the opening of a
#: critical edge half a spacing away, c_g = sqrt(8 / pi) sqrt(1 / 2) = 2 / sqrt(pi): the
#: edge of a growing contact then passes a point as the JKR edge passes its pixel's middle,
#: so the pixel count follows pi a^2 on loading. (It was 1.25, about the mean gap of a
#: bonded flat punch's neighbours, 1.21 K sqrt(dx): with it a point closed whose gap is
#: above the critical opening, the loading edge ran ahead of K_c, and at the lowest loads,
#: where the contact's K sets alpha (4 % of alpha per % of K at P = 0), a Hertz asperity
#: read +3.8 % at 512^2; benchmarks/results/adhesion.md.)
CLOSING_FACTOR = 2.0 / math.sqrt(math.pi)
#: Conjugate-gradient iterations at most per solve, and the relative residual aimed at.
MAX_ITER = 5000
TOLERANCE = 1e-10
#: The preconditioner's precision: float32 FFTs (about half the cost of float64 at 384^2)
#: change only the search directions, not the residual the solve is held to, which is
#: float64: the same iterations and contact sets as a float64 preconditioner on the
#: 9-asperity benchmark path.
PRECONDITIONER_DTYPE = torch.complex64


def inverse_kernel(m: int, side: float, device: torch.device) -> Tensor:
    """(1, M, M // 2 + 1): p_hat / u_hat = pi |k| / L for a cell of side L, E* = 1; 0 at
    k = 0 (a uniform displacement costs no pressure on the periodic half-space)."""
    k = unit_kernel(m, device)
    return torch.where(k > 0, 1.0 / torch.where(k > 0, k, 1.0), 0.0)[None] / float(side)


def forward_kernel(m: int, side: float, device: torch.device) -> Tensor:
    """(1, M, M // 2 + 1): u_hat / p_hat = L / (pi |k|), 0 at k = 0 (``torch_bem``)."""
    return unit_kernel(m, device)[None] * float(side)


def _mean(x: Tensor, mask: Tensor) -> Tensor:
    """(B, 1, 1) mean of x over the mask (float 0/1), 0 where the mask is empty."""
    n = mask.sum(dim=(1, 2), keepdim=True)
    return (x * mask).sum(dim=(1, 2), keepdim=True) / n.clamp_min(1.0)


def _dot(a: Tensor, b: Tensor) -> Tensor:
    return (a * b).sum(dim=(1, 2), keepdim=True)


@dataclass(frozen=True)
class AdhesiveSolution:
    """Contacts of B cells at one mean gap each.

    pressure, gap: (B, M, M) [E*; length]; contact: (B, M, M) bool (g = 0);
    p_star: (B,) mean pressure P* (negative: the cell pulls); alpha: (B,) contact fraction;
    residual: (B,) the solver's relative residual; iterations: conjugate-gradient steps.
    """

    pressure: Tensor
    gap: Tensor
    contact: Tensor
    p_star: Tensor
    alpha: Tensor
    residual: Tensor
    iterations: int


def solve_maugis(
    heights: Tensor,
    side: float,
    mean_gap: Tensor,
    work: float,
    rho: float,
    *,
    gap: Tensor | None = None,
    tolerance: float = TOLERANCE,
    max_iter: int = MAX_ITER,
) -> AdhesiveSolution:
    """Maugis-Dugdale contact of (B, M, M) surfaces at mean gaps (B,) [length].

    work: w [E* length], rho: the range [length] (sigma_0 = w / rho). gap: (B, M, M) start
    (the previous solution of a path), or None: the rigid gap rescaled to the mean gap.
    Raises MetainterfaceError when the residual stays above ``tolerance``.
    """
    if not (work >= 0 and rho > 0):
        raise MetainterfaceError(f"work must be >= 0 and rho > 0, got {work:g}, {rho:g}")
    b, m, _ = heights.shape
    inv = inverse_kernel(m, side, heights.device)
    z = heights
    target = mean_gap.reshape(b, 1, 1).to(z)
    sigma0 = work / rho
    g = z.amax(dim=(1, 2), keepdim=True) - z if gap is None else gap.clone()
    g = g * (target / g.mean(dim=(1, 2), keepdim=True).clamp_min(1e-300))
    t = torch.zeros_like(g)
    g_old = torch.ones_like(target)
    conj = torch.zeros_like(target, dtype=torch.bool)
    cohesive_old = None
    err = torch.full((b,), math.inf, dtype=z.dtype, device=z.device)
    it = 0
    for it in range(1, max_iter + 1):
        pt = displacement(g + z, inv)
        cohesive = (g < rho).to(z.dtype)
        q = pt + sigma0 * cohesive
        free = (g > 0).to(z.dtype)
        q = q - _mean(q, free)
        qf = q * free
        big = _dot(qf, qf)
        err = (big.sqrt() / _dot(pt, pt).sqrt().clamp_min(1e-300)).reshape(-1)
        if bool((err <= tolerance).all()) and it > 1:
            break
        # a change of the cohesive set changes the energy's gradient by a jump: no
        # conjugacy across it (nor across a change of the free set, below)
        if cohesive_old is not None:
            conj = conj & (cohesive == cohesive_old).all(dim=(1, 2), keepdim=True)
        cohesive_old = cohesive
        beta = torch.where(conj, big / g_old, 0.0)
        t = qf + beta * t * free
        g_old = big
        r = displacement(t, inv)
        r = r - _mean(r, free)
        tau = _dot(qf, t) / _dot(r * free, t).clamp_min(1e-300)
        g = torch.clamp_min(g - tau * t, 0.0)
        # points in contact whose gradient asks them to open (q < 0): out again
        opening = (g <= 0) & (q < 0)
        g = torch.where(opening, -tau * q, g)
        conj = ~opening.any(dim=(1, 2), keepdim=True)
        g = g * (target / g.mean(dim=(1, 2), keepdim=True).clamp_min(1e-300))
    if not bool((err <= tolerance).all()):
        raise MetainterfaceError(
            f"adhesive BEM (Maugis-Dugdale) did not converge: residual {float(err.max()):.3g} "
            f"> tolerance {tolerance:g} after {max_iter} iterations"
        )
    pt = displacement(g + z, inv)
    free = (g > 0).to(z.dtype)
    cohesive = (g < rho).to(z.dtype)
    p_star = -_mean(pt + sigma0 * cohesive, free)
    pressure = pt + p_star
    contact = g <= 0
    alpha = contact.to(z.dtype).mean(dim=(1, 2))
    return AdhesiveSolution(pressure, g, contact, p_star.reshape(-1), alpha, err, it)


def _spectral(kernel: Tensor, dtype: torch.dtype) -> Tensor:
    """A real or complex kernel (1 or B, M, M // 2 + 1) as ``_apply`` takes it: complex (a
    real kernel is cast at every product, a copy of the spectrum) and laid out as the
    transform along the columns returns its spectrum (transposed on the CPU), so the
    product is one pass over matching strides. A no-op on a kernel already so."""
    return kernel.to(dtype).transpose(-1, -2).contiguous().transpose(-1, -2)


def _apply(x: Tensor, kernel: Tensor) -> Tensor:
    """(B, M, M) the operator of a real Fourier kernel applied to x (B, M, M); kernel
    (1 or B, M, M // 2 + 1) complex, best from ``_spectral`` (``torch_bem.displacement``'s
    transforms)."""
    m = x.shape[-1]
    spectrum = torch.fft.fft(torch.fft.rfft(x, dim=-1), dim=-2).mul_(kernel)
    return torch.fft.irfft(torch.fft.ifft(spectrum, dim=-2), n=m, dim=-1)


def _bonded(
    z: Tensor,
    c: Tensor,
    contact: Tensor,
    fwd: Tensor,
    p0: Tensor,
    tolerance: float,
    max_iter: int,
    stiffness: Tensor | None = None,
    u0: Tensor | None = None,
) -> tuple[Tensor, Tensor]:
    """Pressures on the contact sets (B, M, M) bool with g = u - z - c = 0 there, p = 0 off
    them: preconditioned conjugate gradients on K_CC p_C = (z + c)_C from p0 (B, M, M) [E*],
    to a relative residual ||(z + c - u)_C|| / ||(z + c)_C|| <= ``tolerance``.

    fwd: (1 or B, M, M // 2 + 1) the compliance u_hat / p_hat; stiffness: its inverse
    (``inverse_kernel``; from fwd when None), the preconditioner; both real or complex. u0:
    the displacement of p0 (B, M, M) [length] where p0 is 0 off the contact, or None.
    Returns p (B, M, M), 0 off the contact, and the relative residual (B,) of the
    iteration (an item above ``tolerance`` did not converge).

    The preconditioner is the compliance's inverse on the whole half-space, kept to the
    contact (as ``torch_bem``'s, Vollebregt 2014): the compliance's condition number grows
    with the contact's size in grid points, its inverse takes most of that away (about 13
    iterations a solve instead of 45-62 on the 9-asperity benchmark cell, at two FFT pairs
    an iteration instead of one). The iteration's vectors hold the contact's points only
    (gathered over the batch; a dot product is a sum per item), so only the FFTs touch the
    whole grid: the contact is a tenth of it or less in a check.
    """
    b, m, _ = z.shape
    n = m * m
    if stiffness is None:
        stiffness = torch.where(fwd > 0, 1.0 / torch.where(fwd > 0, fwd, 1.0), 0.0)
    fwd, stiffness = _spectral(fwd, torch.complex128), _spectral(stiffness, PRECONDITIONER_DTYPE)
    idx = contact.reshape(-1).nonzero().squeeze(1)  # the contact's points, flat over B
    if idx.numel() == 0:  # no contact: no pressure (an FFT of no rows is an error)
        return torch.zeros_like(z), torch.zeros(b, dtype=z.dtype, device=z.device)
    item = torch.div(idx, n, rounding_mode="floor")
    # The rows holding a contact point (of any item): the transforms along the rows run on
    # those only, zero rows transform to zero and the other rows' results are not read (a
    # third to a half of the rows in a check: a quarter of the float64 transform's cost)
    row = torch.div(idx % n, m, rounding_mode="floor")
    rows, rank = torch.unique(row, sorted=True, return_inverse=True)
    pos = (item * rows.numel() + rank) * m + idx % m  # in a (B, rows, M) buffer
    fields = {  # 0 off the contact, always
        t: torch.zeros(b * rows.numel() * m, dtype=t, device=z.device)
        for t in {torch.float64, stiffness.real.dtype}
    }
    spectra = {
        t: torch.zeros(b, m, m // 2 + 1, dtype=k.dtype, device=z.device)
        for t, k in ((torch.float64, fwd), (stiffness.real.dtype, stiffness))
    }

    def apply(kernel: Tensor, v: Tensor) -> Tensor:  # the operator on the contact's points
        t = kernel.real.dtype
        field = fields[t]
        field[pos] = v.to(t)
        spectrum = spectra[t]
        spectrum[:, rows] = torch.fft.rfft(field.view(b, -1, m), dim=-1)
        out = torch.fft.ifft(torch.fft.fft(spectrum, dim=-2).mul_(kernel), dim=-2)[:, rows]
        return torch.fft.irfft(out, n=m, dim=-1).reshape(-1)[pos].to(v.dtype)

    def dot(a: Tensor, v: Tensor) -> Tensor:  # (B,) sums over each item's points
        return torch.zeros(b, dtype=z.dtype, device=z.device).index_add_(0, item, a * v)

    rhs = (z + c).reshape(-1)[idx]
    p = p0.reshape(-1)[idx]
    u = apply(fwd, p) if u0 is None else u0.reshape(-1)[idx]
    r = rhs - u
    scale = dot(rhs, rhs).sqrt().clamp_min(1e-300)
    w = apply(stiffness, r)
    d = w
    rw = dot(r, w)
    rr = dot(r, r)
    for _ in range(max_iter):
        if bool((rr.sqrt() <= tolerance * scale).all()):
            break
        ad = apply(fwd, d)
        step = (rw / dot(d, ad).clamp_min(1e-300))[item]
        p = p.addcmul(step, d)
        r = r.addcmul(step, ad, value=-1.0)
        rr = dot(r, r)
        w = apply(stiffness, r)
        rw_new = dot(r, w)
        # an item already converged has r = 0: beta 0 / 0 -> 0 (clamped), d stays finite
        d = w.addcmul(d, (rw_new / rw.clamp_min(1e-300))[item])
        rw = rw_new
    out = torch.zeros(b * n, dtype=z.dtype, device=z.device)
    out[idx] = p
    return out.view(b, m, m), (rr.sqrt() / scale).reshape(-1)


def _neighbours(mask: Tensor) -> Tensor:
    """(B, M, M) bool: the points with a (periodic) 4-neighbour in ``mask``."""
    out = torch.zeros_like(mask)
    for dim in (1, 2):
        for shift in (1, -1):
            out = out | torch.roll(mask, shift, dims=dim)
    return out


def critical_tension(work: float, spacing: float, edge: float | None = None) -> float:
    """sigma_c = c_e sqrt(2 E* w / dx) [E*]: the tension at which a bonded edge point comes
    off on a grid of spacing dx (Pohrt & Popov 2015), E* = 1, w [E* length]."""
    return (EDGE_FACTOR if edge is None else edge) * math.sqrt(2.0 * work / spacing)


def solve_jkr(
    heights: Tensor,
    side: float,
    mean_gap: Tensor,
    work: float,
    *,
    contact: Tensor | None = None,
    pressure: Tensor | None = None,
    tolerance: float = TOLERANCE,
    max_iter: int = MAX_ITER,
    max_updates: int = 500,
    edge: float | None = None,
) -> AdhesiveSolution:
    """JKR-limit contact of (B, M, M) surfaces at mean gaps (B,) (Pohrt-Popov criterion).

    contact, pressure: the previous state of a path (hysteresis: a point that touched stays
    bonded until its tension exceeds sigma_c), or None: start from the rigid overlap.
    Raises MetainterfaceError where a bonded solve does not reach ``tolerance`` in
    ``max_iter`` iterations (not a contact state), or the contact set does not settle in
    ``max_updates`` updates.
    """
    b, m, _ = heights.shape
    fwd = forward_kernel(m, side, heights.device)
    z = heights
    spacing = side / m
    sigma_c = critical_tension(work, spacing, edge)
    # mean gap = mean(u - z - c), mean u = 0: c follows from the mean gap
    c = -z.mean(dim=(1, 2), keepdim=True) - mean_gap.reshape(b, 1, 1).to(z)
    if contact is None:
        contact = (-z - c) <= 0
    g_close = CLOSING_FACTOR * math.sqrt(2.0 * work * spacing)
    p = torch.zeros_like(z) if pressure is None else pressure
    stiffness = _spectral(inverse_kernel(m, side, z.device), PRECONDITIONER_DTYPE)
    fwd = _spectral(fwd, torch.complex128)
    res = torch.zeros(b, dtype=z.dtype, device=z.device)
    came_off = torch.zeros_like(contact)
    u = None  # the displacement of p where p is 0 off the contact, else None
    resolves = 0  # solves of a stable set whose true residual was above the tolerance
    for _ in range(max_updates):
        p, res = _bonded(z, c, contact, fwd, p, tolerance, max_iter, stiffness, u)
        if not bool((res <= tolerance).all()):
            # a bonded solve stopped short is not a contact state: its pressures, and the
            # points it lets come off, are the iteration's, not the contact's
            raise MetainterfaceError(
                f"adhesive BEM (JKR) did not converge: conjugate-gradient residual "
                f"{float(res.max()):.3g} > tolerance {tolerance:g} after {max_iter} iterations"
            )
        # the displacement afresh (carried with the iterates it would cost a full-grid
        # update an iteration, more than this FFT pair), so the residual below is the true one
        u = _apply(p, fwd)
        g = u - z - c
        beside = _neighbours(contact) & ~contact
        attach = ~contact & ((g < 0) | (beside & ~came_off & (g < g_close)))
        detach = contact & (p < -sigma_c)
        if not bool((attach | detach).any()):
            # the state returned; the iteration's residual is a recursion's, which drifts by
            # rounding: a true residual above the tolerance takes another solve of the set
            rhs_norm = ((z + c) * contact).square().sum(dim=(1, 2)).sqrt()
            res = (g * contact).square().sum(dim=(1, 2)).sqrt() / rhs_norm.clamp_min(1e-300)
            if bool((res <= tolerance).all()):
                break
            resolves += 1
            if resolves > 3:  # rounding holds the true residual above what was asked
                raise MetainterfaceError(
                    f"adhesive BEM (JKR) did not converge: residual {float(res.max()):.3g} > "
                    f"tolerance {tolerance:g} (the conjugate gradient's own reads below it)"
                )
            continue
        came_off = came_off | detach
        contact = (contact | attach) & ~detach
        if bool(detach.any()):
            u = None  # p loses the points that came off: its displacement changes
    else:
        raise MetainterfaceError(
            f"adhesive BEM (JKR) found no stable contact set in {max_updates} updates"
        )
    g = g * ~contact
    p_star = p.mean(dim=(1, 2))
    alpha = contact.to(z.dtype).mean(dim=(1, 2))
    return AdhesiveSolution(p, g, contact, p_star, alpha, res, 0)
