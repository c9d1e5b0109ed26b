"""Periodic frictionless normal contact with the boundary element method, in torch.

A rigid periodic surface z (tips up) is pressed on an elastic half-space of E* = 1 under a
prescribed mean pressure P* (paper sec. 4.1, as ``bem``'s Tamaas engine). The normal
displacement of a periodic half-space under pressure p is diagonal in Fourier space
(Johnson, *Contact Mechanics*, 1985, sec. 13; Stanley & Kato 1997):

    u_hat(q) = 2 p_hat(q) / (E* |q|),   |q| = 2 pi |k| / L,   u_hat(0) = 0,

applied with real-input FFTs (half the spectrum; ``displacement``), the kernel built once
per grid size and device. The contact problem (p >= 0, gap g = u - z - c >= 0, p g = 0,
mean p = P*) is solved by the constrained conjugate gradient of Polonsky & Keer (Wear 231,
1999, 206-219) with the mean-pressure constraint of Rey, Anciaux & Molinari (Comput. Mech.
60, 2017, 69-81): a conjugate gradient on the gap restricted to the points in contact, a projection
onto p >= 0 that puts pressure back where the surface overlaps, and a rescaling to the
prescribed mean pressure after each step.

The conjugate gradient is preconditioned with the inverse of the compliance on the whole
half-space, the stiffness p_hat / u_hat = E* |q| / 2 (an FFT-based preconditioner as in
Vollebregt, J. Comput. Phys. 257, 2014, 333-351): each step's gap on the contact is turned
into the pressure that would close it on an unbounded contact, kept to the contact and
centred there so that it moves no load. That costs a third FFT pair per iteration and takes
2-3x fewer iterations (the compliance's condition number grows with M; its inverse takes
most of that away), the more so on large contacts and fine grids
(``benchmarks/results/bem_engines.md``). The solution and the convergence measure are
unchanged.

Convergence is measured as Tamaas 2.9 measures it, so one tolerance means the same for
both engines: the complementarity error

    err = | sum p (g - min g) | / ( |sum p| sigma_z ),

sigma_z the standard deviation of the surface, g the (centred) gap of the iteration.
A load path of ascending pressures starts each solve from the previous pressure field
rescaled to the new mean, as Tamaas does. The first load starts from a uniform pressure, or,
given where a forward model puts each asperity's contact edge (``contact_start``), from
square-root pressure profiles inside those edges: half the iterations of a uniform start. Two
departures from Tamaas, both where it fails: a cold start takes at least two iterations
(after one, that error reads 0 on a flat punch with the pressure still uniform), and a load
whose warm start is a contact of one grid point (no conjugate direction: 0 / 0) starts
again from a uniform pressure instead of failing.

float64 throughout: float32 does not reach the paper's 1e-11. Several height maps of one
grid size are solved as one batch (``solve_batch``), each item frozen as soon as it
converges; that is how a GPU is kept busy by a sweep.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from typing import Any

import numpy as np
import torch

from metainterface.errors import MetainterfaceError

_KERNELS: dict[tuple[int, str], torch.Tensor] = {}


def unit_kernel(m: int, device: torch.device) -> torch.Tensor:
    """(M, M // 2 + 1) float64: u_hat / p_hat of a cell of side L = 1, E* = 1, laid out for
    ``rfft2``: 1 / (pi |k|) with k the integer wave vector; 0 at k = 0 (the mean
    displacement is free). Scale by L for a cell of side L. Cached per (M, device)."""
    key = (m, str(device))
    kernel = _KERNELS.get(key)
    if kernel is None:
        kx = torch.fft.fftfreq(m, d=1.0 / m, dtype=torch.float64, device=device)
        ky = torch.fft.rfftfreq(m, d=1.0 / m, dtype=torch.float64, device=device)
        k = torch.sqrt(kx[:, None] ** 2 + ky[None, :] ** 2)
        k[0, 0] = math.inf  # 2 / (E* q) with q = 2 pi k / L -> L / (pi k); zero mean mode
        kernel = 1.0 / (math.pi * k)
        _KERNELS[key] = kernel
    return kernel


def contact_start(heights: np.ndarray, owner: np.ndarray, depth: np.ndarray) -> np.ndarray | None:
    """A first guess of a solve's pressure from a forward model's contacts, or None.

    heights: (M, M) z [length], tips up; owner: (M, M) asperity index of each point;
    depth: (N,) the depth below each asperity's tip of its contact edge in the model,
    c a^gamma [length] (0 out of contact). Inside each edge the pressure rises as the
    square root of the depth to it, the shape of a Hertz contact's, to any scale (a solve
    rescales it to its load). None where the model puts no asperity in contact.
    """
    depth = np.asarray(depth, dtype=np.float64)
    if not np.any(depth > 0):
        return None
    z = torch.as_tensor(np.asarray(heights, dtype=np.float64))
    own = torch.as_tensor(np.asarray(owner)).long().reshape(z.shape)
    tip = torch.full((depth.size,), -math.inf, dtype=torch.float64)
    tip = tip.scatter_reduce(0, own.reshape(-1), z.reshape(-1), reduce="amax")
    p = (torch.as_tensor(depth)[own] - (tip[own] - z)).clamp_min_(0.0).sqrt_()
    return p.numpy() if bool((p > 0).any()) else None


def displacement(p: torch.Tensor, kernel: torch.Tensor) -> torch.Tensor:
    """(B, M, M) surface displacement of (B, M, M) pressures; kernel (B or 1, M, M//2+1)."""
    m = p.shape[-1]
    # rfft along rows, then a complex fft along columns: measured faster than rfft2 on CPU
    spectrum = torch.fft.fft(torch.fft.rfft(p, dim=-1), dim=-2).mul_(kernel)
    return torch.fft.irfft(torch.fft.ifft(spectrum, dim=-2), n=m, dim=-1)


def _dot(a: torch.Tensor, b: torch.Tensor) -> torch.Tensor:
    """(B, 1, 1) sum over each item of a * b, both (B, M, M) contiguous: one pass (a batched
    matrix product), where (a * b).sum() takes two."""
    n = a.shape[0]
    return torch.bmm(a.reshape(n, 1, -1), b.reshape(n, -1, 1))


def solve_batch(
    heights: torch.Tensor,
    kernel: torch.Tensor,
    loads: torch.Tensor,
    pressure: torch.Tensor | None,
    *,
    tolerance: float,
    max_iter: int,
    check_every: int = 1,
) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor, torch.Tensor]:
    """Solve B contacts at once by Polonsky-Keer-Rey (see the module docstring).

    heights: (B, M, M) z [length], tips up; kernel: (B or 1, M, M // 2 + 1) the scaled
    ``unit_kernel``; loads: (B,) mean pressures P* > 0; pressure: (B, M, M) first guess
    (rescaled to each load), or None for a uniform one. check_every: iterations between
    convergence checks (a check synchronises a GPU with the host).

    Returns (pressure (B, M, M), gap (B, M, M) [length, min 0], error (B,), iterations
    (B,)); an item that did not converge has error > tolerance.
    """
    b, m, _ = heights.shape
    n_points = m * m
    dev = heights.device
    target = loads.reshape(b, 1, 1).to(heights)
    if pressure is None:
        p = target.expand(b, m, m).clone()
    else:
        mean = pressure.mean(dim=(1, 2), keepdim=True)
        ok = mean > 0
        p = torch.where(ok, pressure * (target / torch.where(ok, mean, 1.0)), target)
    sigma = heights.reshape(b, -1).std(dim=1, correction=0).reshape(b, 1, 1)
    norm = (target * n_points) * sigma  # |sum p| sigma_z (sum p = P* M^2 after rescaling)

    out_p = torch.empty_like(p)
    out_err = torch.full((b,), math.inf, dtype=torch.float64, device=dev)
    out_iter = torch.zeros(b, dtype=torch.int64, device=dev)
    rows = torch.arange(b, device=dev)  # the items still iterating, as rows of the originals
    z, ker, tgt, nrm = heights, kernel, target, norm
    # the preconditioner: the half-space's stiffness, the compliance's inverse (0 at k = 0)
    stf = torch.where(kernel > 0, kernel.reciprocal(), 0.0)
    t = torch.zeros_like(p)
    g_old = torch.ones(b, 1, 1, dtype=torch.float64, device=dev)
    conjugate = torch.zeros(b, 1, 1, dtype=torch.bool, device=dev)
    it = 0
    # From a uniform pressure the first gap is -z, constant on any flat part of the surface:
    # the error (new pressure, that gap) can read 0 there after one step (a flat punch does;
    # so does Tamaas). A cold start takes at least two iterations.
    min_iter = 2 if pressure is None else 1
    # Every field operation below is one pass over memory: float 0/1 masks (sign of p >= 0)
    # and batched dot products instead of torch.where and masked sums, which cost 2-10x more.
    while True:
        it += 1
        g = displacement(p, ker).sub_(z)  # gap, up to a constant
        inside = torch.sign(p)  # 1 in contact, 0 out (p >= 0)
        count = inside.sum(dim=(1, 2), keepdim=True).clamp_min_(1.0)
        g.sub_(_dot(g, inside) / count)  # centred on the contact
        g_in = g * inside
        # preconditioned gap: the pressure that would close it on a whole half-space, kept to
        # the contact and centred there (the direction moves no load)
        w = displacement(g_in, stf).mul_(inside)
        w.sub_(inside * (_dot(w, inside) / count))
        big_g = _dot(g_in, w)
        beta = torch.where(conjugate, big_g / g_old, 0.0)
        t = torch.addcmul(w, t.mul_(beta), inside)  # search direction, 0 out of contact
        g_old = big_g
        r = displacement(t, ker)
        # sum over the contact of (r - mean r) t = r.t - mean(r) sum(t), t being 0 outside
        r_mean = _dot(r, inside) / count
        tau = _dot(g, t) / (_dot(r, t) - r_mean * t.sum(dim=(1, 2), keepdim=True))
        p = torch.addcmul(p, t, tau, value=-1.0).clamp_min_(0.0)
        # where the surface overlaps with no pressure, put pressure back (Polonsky & Keer):
        # p = -tau g at the points with p = 0 and g < 0
        refill = (g * -tau).clamp_min_(0.0)
        refill = torch.addcmul(refill, torch.sign(p), refill, value=-1.0)
        p.add_(refill)
        conjugate = refill.amax(dim=(1, 2), keepdim=True) <= 0
        p.mul_(tgt / p.mean(dim=(1, 2), keepdim=True))
        if it % check_every and it < max_iter:
            continue
        g_min = g.amin(dim=(1, 2), keepdim=True)
        err = ((_dot(p, g) - g_min * tgt * n_points).abs() / nrm).reshape(-1)
        if torch.isnan(err).any():
            bad = int(torch.isnan(err).nonzero()[0, 0])
            raise ArithmeticError(
                f"the solve of item {int(rows[bad])} produced NaN (a contact of one grid point?)"
            )
        done = ((err <= tolerance) & (it >= min_iter)) | (it >= max_iter)
        if bool(done.any()):
            idx = rows[done]
            out_p[idx] = p[done]
            out_err[idx] = err[done]
            out_iter[idx] = it
            keep = ~done
            if not bool(keep.any()):
                break
            rows, p, t, z, tgt, nrm = rows[keep], p[keep], t[keep], z[keep], tgt[keep], nrm[keep]
            g_old, conjugate = g_old[keep], conjugate[keep]
            if ker.shape[0] > 1:
                ker, stf = ker[keep], stf[keep]
    # the gap of the final pressure, shifted to min 0 (as Tamaas's displacement - z): 0 on
    # the contact to within the tolerance, > 0 elsewhere
    gap = displacement(out_p, kernel).sub_(heights)
    gap.sub_(gap.amin(dim=(1, 2), keepdim=True))
    return out_p, gap, out_err, out_iter


def solve_path(
    heights: np.ndarray,
    cell_side: float,
    loads: np.ndarray,
    *,
    device: torch.device,
    tolerance: float,
    max_iter: int,
    on_load: Callable[[int, np.ndarray, np.ndarray, float, float], Any],
    check_every: int | None = None,
    start: np.ndarray | None = None,
) -> None:
    """One cell at ascending mean pressures ``loads`` (K,), each load warm-started from the
    previous one, the first from ``start`` (M, M) (any scale, e.g. ``contact_start``) or a
    uniform pressure. on_load(i, pressure (M, M), gap (M, M), error, seconds) as each load
    is solved (numpy, float64); raises ArithmeticError(i, why) on NaN at load i.
    Non-convergence is the caller's to judge from ``error``."""
    z = torch.as_tensor(np.ascontiguousarray(heights, dtype=np.float64), device=device)[None]
    m = z.shape[-1]
    kernel = (unit_kernel(m, device) * float(cell_side))[None]
    every = (1 if device.type == "cpu" else 4) if check_every is None else check_every
    p = None if start is None else torch.as_tensor(start, device=device).reshape(1, m, m)
    for i, load in enumerate(np.asarray(loads, dtype=np.float64)):
        t0 = time.perf_counter()
        target = torch.tensor([load], dtype=torch.float64, device=device)
        try:
            try:
                p, gap, err, _ = solve_batch(
                    z, kernel, target, p, tolerance=tolerance, max_iter=max_iter, check_every=every
                )
            except ArithmeticError:
                if p is None:
                    raise
                # a previous contact of a grid point or two leaves the conjugate gradient no
                # direction (0 / 0): start this load afresh from a uniform pressure
                p, gap, err, _ = solve_batch(
                    z,
                    kernel,
                    target,
                    None,
                    tolerance=tolerance,
                    max_iter=max_iter,
                    check_every=every,
                )
        except ArithmeticError as exc:
            raise ArithmeticError(i, str(exc)) from None
        pressure, gap_np = p[0].cpu().numpy(), gap[0].cpu().numpy()
        on_load(i, pressure, gap_np, float(err[0]), time.perf_counter() - t0)


def solve_paths(
    heights: np.ndarray,
    cell_sides: np.ndarray,
    loads: np.ndarray,
    *,
    device: torch.device,
    tolerance: float,
    max_iter: int,
    on_load: Callable[[int, np.ndarray, np.ndarray, np.ndarray, float], Any],
    check_every: int | None = None,
) -> None:
    """B cells of one grid size along their load paths, solved as one batch per load.

    heights: (B, M, M); cell_sides: (B,); loads: (B, K), ascending along K. on_load(k,
    pressures (B, M, M), gaps (B, M, M), errors (B,), seconds) after each load k (numpy).
    Raises ArithmeticError(k, why) on NaN at load k.
    """
    z = torch.as_tensor(np.ascontiguousarray(heights, dtype=np.float64), device=device)
    b, m, _ = z.shape
    sides = torch.as_tensor(np.asarray(cell_sides, dtype=np.float64), device=device)
    kernel = unit_kernel(m, device)[None] * sides.reshape(b, 1, 1)
    loads = np.asarray(loads, dtype=np.float64)
    every = (1 if device.type == "cpu" else 4) if check_every is None else check_every
    p = None
    for k in range(loads.shape[1]):
        start = time.perf_counter()
        target = torch.as_tensor(loads[:, k], device=device)
        try:
            p, gap, err, _ = solve_batch(
                z, kernel, target, p, tolerance=tolerance, max_iter=max_iter, check_every=every
            )
        except ArithmeticError as exc:
            raise ArithmeticError(k, str(exc)) from None
        on_load(
            k, p.cpu().numpy(), gap.cpu().numpy(), err.cpu().numpy(), time.perf_counter() - start
        )


def batch_size(grid: int, device: torch.device) -> int:
    """Designs solved together on ``device``: 1 on the CPU (a batch is no faster there);
    on a GPU as many as about a quarter of its free memory holds (some 30 M x M float64
    fields per design), at most 32."""
    if device.type != "cuda":
        return 1
    free, _ = torch.cuda.mem_get_info(device)
    return int(max(1, min(32, free // 4 // (30 * 8 * grid * grid))))


def check_converged(
    error: float, tolerance: float, max_iter: int, index: int, total: int, load: float
) -> None:
    """Raise the one-line error of a solve that did not converge (load ``index`` of
    ``total``, 0-based index)."""
    if not error <= tolerance:
        raise MetainterfaceError(
            f"BEM did not converge at load {index + 1} of {total} (P* = {load:.6g}): "
            f"residual {error:.3g} > tolerance {tolerance:g} after {max_iter} iterations"
        )
