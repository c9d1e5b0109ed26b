"""Training targets made the way friction laws arrive, for the friction-law network.

The shipped network reads exact cell curves that end at Delta_max, with their exact
stiffness. A friction law turned into alpha(P*) ends wherever the measurement stopped, comes
as a few points with no stiffness column, and is seldom exactly the curve of any cell. The
friction-law network is fine-tuned from the shipped one on targets made from a dataset's
cells to look like that:

- ``cut``: the cell's own curve ended at an indentation Delta_L drawn log-uniformly in
  [min_end, 1] Delta_max, given by M uniform pressures (M from :data:`ROWS`);
- ``warped``: the same times a smooth factor in [1 - warp, 1 + warp], made monotone again: a
  curve near the cells' curves but not on them;
- ``shaped``: a law shape (power, saturating, bilinear, linear with an offset that builds up,
  or a mix of two) through the end point (P*_L, alpha_L) of a cut curve: a law of the size
  that cell reaches.

Every one is read with :func:`~metainterface.physics.curves.normalised_from_points`, the
function that reads a target without stiffness in use. The loss on them is the relative
curve error on the target itself: warped and shaped targets have no known design.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import torch
from torch import Tensor
from tqdm.auto import tqdm

from metainterface.errors import MetainterfaceError
from metainterface.physics.cell import CellSettings
from metainterface.physics.curves import (
    features_from_normalised,
    normalised_from_points,
    sweep,
)
from metainterface.physics.metrics import interp
from metainterface.surrogate.data import Split
from metainterface.surrogate.loss import CurveTargets

#: The point counts a made target is given by (the origin included), drawn uniformly.
ROWS = (6, 10, 20, 40, 80)

KINDS = ("cut", "warped", "shaped")


@dataclass(frozen=True)
class LawTargets:
    """How friction-law-like targets are made from a dataset's cells.

    Attributes
    ----------
    copies : int
        Targets made from each cell (each with its own end, points and kind).
    min_end : float
        Smallest end indentation Delta_L / Delta_max, in (0, 1].
    warp : float
        Largest relative change of alpha by a warp, in [0, 0.9].
    shares : tuple of three floats
        Shares of cut, warped and shaped targets (normalised to sum 1).
    delta_samples : int
        Delta samples of each cell's curve before it is cut and resampled.
    """

    copies: int = 2
    min_end: float = 0.15
    warp: float = 0.15
    shares: tuple[float, float, float] = (0.4, 0.3, 0.3)
    delta_samples: int = 256

    def __post_init__(self) -> None:
        check_counts(self.copies, self.min_end, self.delta_samples)
        if not 0 <= self.warp <= 0.9:
            raise MetainterfaceError(f"warp must be in [0, 0.9], got {self.warp}")
        if len(self.shares) != 3 or min(self.shares) < 0 or sum(self.shares) <= 0:
            raise MetainterfaceError(
                f"shares must be three numbers >= 0 with a positive sum, got {self.shares}"
            )


def check_counts(copies: object, min_end: float, delta_samples: int) -> None:
    """The settings every kind of made target shares (``LawTargets``,
    ``adhesive.AdhesiveTargets``): a one-line error for the first out of range."""
    if not (isinstance(copies, int) and 1 <= copies <= 100):
        raise MetainterfaceError(f"copies must be a whole number in [1, 100], got {copies}")
    if not 0 < min_end <= 1:
        raise MetainterfaceError(f"min_end must be in (0, 1], got {min_end}")
    if not 8 <= delta_samples <= 100_000:
        raise MetainterfaceError(f"delta_samples must be in [8, 100000], got {delta_samples}")


def law_split(
    split: Split,
    settings: CellSettings,
    seed: int,
    spec: LawTargets | None = None,
    chunk: int = 4096,
    progress: bool = False,
) -> Split:
    """Friction-law-like targets (S copies rows) made from the cells of ``split`` (S rows).

    The features are float32 (S copies, 2 n_steps + 2); gamma and h are the source cells'
    (the parameters of cut targets, an approximation for the others); the category is the
    kind (``cut``, ``warped``, ``shaped``). The same seed gives the same targets.
    """
    spec = spec or LawTargets()
    gen = torch.Generator().manual_seed(int(seed))
    gamma = split.gamma.cpu().repeat(spec.copies, 1).double()
    h = split.h.cpu().repeat(spec.copies, 1).double()
    total = gamma.shape[0]
    end = torch.exp(torch.rand(total, generator=gen, dtype=torch.float64) * -math.log(spec.min_end))
    end = end * spec.min_end  # log-uniform in [min_end, 1]
    shares = torch.tensor(spec.shares, dtype=torch.float64)
    kind = torch.multinomial(shares / shares.sum(), total, replacement=True, generator=gen)
    rows = torch.tensor(ROWS)[torch.randint(len(ROWS), (total,), generator=gen)]
    warp = _warps(total, spec.warp, gen)  # (total, 4) coefficients
    shape = _shapes(total, gen)  # (total, 10) parameters
    n = settings.n_steps
    alpha_hat = torch.empty(total, n)
    s_hat = torch.empty(total, n)
    p_max = torch.empty(total)
    a_max = torch.empty(total)
    unit = torch.linspace(0, 1, spec.delta_samples, dtype=torch.float64)
    chunks = range(0, total, chunk)
    for lo in tqdm(chunks, desc="law targets", unit="chunk", disable=not progress):
        sl = slice(lo, min(lo + chunk, total))
        delta = unit[None] * (end[sl] * settings.delta_max)[:, None]
        sw = sweep(gamma[sl], h[sl], settings, delta=delta)
        zeros = torch.zeros_like(sw.p_star[:, :1])
        p_dense = torch.cat([zeros, sw.p_star], -1)
        a_dense = torch.cat([zeros, sw.alpha], -1)
        for m in ROWS:
            pick = torch.nonzero(rows[sl] == m).flatten()
            if pick.numel() == 0:
                continue
            x = torch.linspace(0, 1, m, dtype=torch.float64)[None].expand(pick.numel(), m)
            p = x * p_dense[pick, -1:]
            a = interp(p, p_dense[pick], a_dense[pick])
            k = kind[sl][pick]
            a = torch.where((k == 1)[:, None], _warped(a, x, warp[sl][pick]), a)
            a = torch.where((k == 2)[:, None], a[:, -1:] * _shaped(x, shape[sl][pick]), a)
            out = normalised_from_points(p, a, n)
            idx = pick + lo
            alpha_hat[idx], s_hat[idx] = out[0].float(), out[1].float()
            p_max[idx], a_max[idx] = out[2].float(), out[3].float()
    targets = CurveTargets(alpha_hat, s_hat, p_max, a_max)
    features = features_from_normalised(alpha_hat, s_hat, p_max, a_max)
    category = np.asarray(KINDS, dtype=object)[kind.numpy()].astype(str)
    return Split(features, targets, gamma.float(), h.float(), category)


def _warps(total: int, warp: float, gen: torch.Generator) -> Tensor:
    """(total, 4): an amplitude in [-warp, warp] and three shape coefficients."""
    amp = (2 * torch.rand(total, 1, generator=gen, dtype=torch.float64) - 1) * warp
    return torch.cat([amp, torch.randn(total, 3, generator=gen, dtype=torch.float64)], -1)


def _warped(a: Tensor, x: Tensor, c: Tensor) -> Tensor:
    """alpha (B, M) at x = P*/P*_L (B, M) times 1 + amp w(x), |w| <= 1, kept monotone."""
    w = (
        c[:, 1:2] * (2 * x - 1)
        + c[:, 2:3] * torch.sin(2 * math.pi * x)
        + c[:, 3:4] * torch.sin(3 * math.pi * x)
    )
    w = w / w.abs().amax(-1, keepdim=True).clamp_min(1e-12)
    return torch.cummax(a * (1 + c[:, :1] * w), -1).values


def _shapes(total: int, gen: torch.Generator) -> Tensor:
    """(total, 10) uniform draws: the family, its parameters, a second family and the mix."""
    return torch.rand(total, 10, generator=gen, dtype=torch.float64)


def _family(x: Tensor, which: Tensor, u: Tensor) -> Tensor:
    """Law shapes f(x) on [0, 1] with f(0) = 0, f(1) = 1: power x^m (m in [0.3, 1.2]),
    saturating (scale in [0.08, 1.5]), bilinear (knee in [0.1, 0.8], slope ratio in
    [0.1, 2]), linear with an offset that builds up (slope in [0.2, 1], offset in
    [0.05, 0.6], scale in [0.02, 0.2]); ``which`` (B,) picks the family, u (B, 3) in [0, 1]."""
    u0, u1, u2 = u[:, :1], u[:, 1:2], u[:, 2:3]
    power = x ** (0.3 + 0.9 * u0)
    c = 0.08 + 1.42 * u0
    saturating = (1 - torch.exp(-x / c)) / (1 - torch.exp(-1 / c))
    knee, ratio = 0.1 + 0.7 * u0, 0.1 + 1.9 * u1
    bilinear = torch.where(x < knee, x, knee + ratio * (x - knee)) / (knee + ratio * (1 - knee))
    mu, off, scale = 0.2 + 0.8 * u0, 0.05 + 0.55 * u1, 0.02 + 0.18 * u2
    offset = mu * x + off * (1 - torch.exp(-x / scale))
    offset = offset / offset[:, -1:]
    shapes = torch.stack([power, saturating, bilinear, offset])  # (4, B, M)
    return shapes.gather(0, which[None, :, None].expand(1, *x.shape))[0]


def _shaped(x: Tensor, u: Tensor) -> Tensor:
    """A law shape (B, M) on x (B, M) from the draws u (B, 10); a third of them mix two."""
    first = _family(x, (u[:, 0] * 4).long().clamp(max=3), u[:, 1:4])
    second = _family(x, (u[:, 4] * 4).long().clamp(max=3), u[:, 5:8])
    mix = torch.where(u[:, 8:9] < 1 / 3, u[:, 9:10], torch.ones_like(u[:, 9:10]))
    return mix * first + (1 - mix) * second
