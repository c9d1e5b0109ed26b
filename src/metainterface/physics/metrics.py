"""How a curve compares with another: interpolation on a pressure grid, the relative L2
error, the share of a target's load range a design reaches (coverage), and the one curve
error combining fit and coverage (the error a design reports)."""

from __future__ import annotations

import numpy as np
import torch
from torch import Tensor


def interp(xq: Tensor, xp: Tensor, *fps: Tensor) -> Tensor | tuple[Tensor, ...]:
    """Batched, differentiable linear interpolation, held constant beyond the ends.

    xq: (B, Q) query points; xp: (B, K) non-decreasing knots; each fp: (B, K) values.
    Returns one (B, Q) tensor per fp (a tuple if several); the knot search is shared.
    Zero-width knot intervals (repeated xp) are safe.
    """
    idx, w, _, _ = interp_weights(xq, xp)
    out = []
    for fp in fps:
        f0 = fp.gather(-1, idx - 1)
        out.append(f0 + w * (fp.gather(-1, idx) - f0))
    return out[0] if len(out) == 1 else tuple(out)


def interp_weights(xq: Tensor, xp: Tensor) -> tuple[Tensor, Tensor, Tensor, Tensor]:
    """The knots and weights of :func:`interp`: f(xq) = (1 - w) fp[idx - 1] + w fp[idx].

    xq (B, Q), xp (B, K) -> idx (B, Q) in [1, K - 1], w (B, Q) in [0, 1] (differentiable in
    xq and xp), the interval's width xp[idx] - xp[idx - 1] (B, Q), and the unclamped
    ratio (xq - xp[idx - 1]) / width (B, Q; any value where the width is 0): w depends on
    the knots only where the width is positive and the ratio in [0, 1].
    """
    k = xp.shape[-1]
    idx = torch.searchsorted(xp.detach().contiguous(), xq.detach().contiguous()).clamp(1, k - 1)
    x0, x1 = xp.gather(-1, idx - 1), xp.gather(-1, idx)
    width = x1 - x0
    has_width = width > 0
    ratio = (xq - x0) / torch.where(has_width, width, 1.0)
    return idx, torch.where(has_width, ratio.clamp(0, 1), 0.0), width, ratio


def window_mean(xq: Tensor, half: Tensor | float, xp: Tensor, fp: Tensor) -> Tensor:
    """The mean of :func:`interp`'s curve over [xq - half, xq + half]: a box-smoothed read.

    xq: (B, Q) query points; half: the window's half-width, > 0 (a number, or (B,) / (B, Q));
    xp: (B, K) non-decreasing knots, fp: (B, K) values. Returns (B, Q). A step in fp
    (repeated knots) becomes a ramp of width 2 half, so the read is differentiable in where
    the step is (a plain read sees only the values either side of it). Exact: the
    difference of the piecewise-linear curve's integral, held constant beyond the ends.
    """
    half_t = torch.as_tensor(half, dtype=xq.dtype, device=xq.device)
    if half_t.dim() == 1:
        half_t = half_t[:, None]
    width = xp[..., 1:] - xp[..., :-1]
    # the integral from xp[0] to each knot, (B, K), by trapezoids (0 for a repeated knot)
    area = torch.cumsum(0.5 * width * (fp[..., 1:] + fp[..., :-1]), dim=-1)
    area = torch.cat([torch.zeros_like(area[..., :1]), area], dim=-1)

    def integral(x: Tensor) -> Tensor:
        idx, w, span, _ = interp_weights(x, xp)
        f0, f1 = fp.gather(-1, idx - 1), fp.gather(-1, idx)
        inside = area.gather(-1, idx - 1) + span * w * (f0 + 0.5 * w * (f1 - f0))
        below = torch.clamp_max(x - xp[..., :1], 0.0) * fp[..., :1]
        above = torch.clamp_min(x - xp[..., -1:], 0.0) * fp[..., -1:]
        return inside + below + above

    return (integral(xq + half_t) - integral(xq - half_t)) / (2.0 * half_t)


def relative_l2(values: Tensor, reference: Tensor) -> Tensor:
    """||values - reference||_2 / ||reference||_2 along the last axis: (B, M) -> (B,).

    The relative curve error of the package, with alpha curves on the target's pressures.
    """
    return torch.linalg.vector_norm(values - reference, dim=-1) / torch.linalg.vector_norm(
        reference, dim=-1
    )


def coverage(p_star: Tensor, p_reach: Tensor) -> Tensor:
    """The fraction of a target's load range that a design reaches: (B, M), (B,) -> (B,).

    p_star: the target's pressures (ascending, from 0 or near it); p_reach: the design's
    largest pressure P*_max. P*_max / p_last clipped to [0, 1]: the load range is counted
    from zero load, 1 when the design reaches the target's largest load.
    """
    return (p_reach / p_star[..., -1]).clamp(0.0, 1.0)


def curve_error(alpha: Tensor, reference: Tensor, p_star: Tensor, p_reach: Tensor) -> Tensor:
    """The package's one curve error: sqrt(fit^2 + (1 - coverage)^2), (B, M) x3, (B,) -> (B,).

    fit = ||alpha - alpha_t||_2 / ||alpha_t||_2 over the target's pressures p_star that the
    design reaches (p <= p_reach, its P*_max; 0 when none with alpha_t > 0 is reached);
    coverage = :func:`coverage`. A design that meets the whole target scores its plain
    relative L2 error; one that stops short is charged the load range it misses, whatever
    its curve does beyond its reach (the convention of docs/concepts/errors.md).
    Accepts numpy arrays too (then returns numpy).
    """
    as_numpy = not isinstance(alpha, Tensor)
    if as_numpy:
        alpha, reference, p_star, p_reach = (
            torch.as_tensor(np.asarray(v, dtype=np.float64))
            for v in (alpha, reference, p_star, p_reach)
        )
    reached = p_star <= p_reach[..., None]
    num = torch.linalg.vector_norm(torch.where(reached, alpha - reference, 0.0), dim=-1)
    den = torch.linalg.vector_norm(torch.where(reached, reference, 0.0), dim=-1)
    fit = torch.where(den > 0, num / torch.where(den > 0, den, 1.0), 0.0)
    err = torch.sqrt(fit**2 + (1.0 - coverage(p_star, p_reach)) ** 2)
    return err.numpy() if as_numpy else err
