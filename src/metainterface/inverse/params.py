"""How the refinement's unbounded parameters map to designs (paper appendix C).

gamma = gamma_min + (gamma_max - gamma_min) sigmoid(r_gamma) and heights
h = [0, Delta_max softplus(r_h)] (the first asperity is the anchor at h = 0), re-sorted at
every evaluation with each gamma kept with its h. A parameterisation with ``fixed_gamma``
optimises the heights only: the Hertz-only baseline is ``HERTZ`` (gamma = 2 everywhere).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import torch
from torch import Tensor
from torch.nn import functional as nnf

from metainterface.errors import MetainterfaceError
from metainterface.physics.cell import CellSettings

DTYPE = torch.float64

# The derivatives of softplus (beta 1, threshold 20, nnf.softplus's defaults) and sigmoid,
# given the upstream gradient: the kernels autograd itself runs for them.
_softplus_back = torch.ops.aten.softplus_backward
_sigmoid_back = torch.ops.aten.sigmoid_backward

#: How far inside the bounds :meth:`Parameterisation.from_design` puts a start: gamma at
#: least this fraction of its range from either bound, height gaps at least this fraction of
#: Delta_max. Closer, the sigmoid and softplus flatten and a start on a bound cannot move.
START_MARGIN = 0.01


@dataclass(frozen=True)
class Parameterisation:
    """Unbounded parameters (B, D) <-> designs (gamma, h) (B, N).

    fixed_gamma: None to optimise gamma and h (D = 2N - 1), or a shape exponent that every
    asperity keeps while only the heights move (D = N - 1).
    """

    fixed_gamma: float | None = None

    def __post_init__(self) -> None:
        g = self.fixed_gamma
        if g is not None and not (isinstance(g, int | float) and 1.0 < g < float("inf")):
            raise MetainterfaceError(f"fixed_gamma must be a number > 1, got {g!r}")

    def rows(self, index: Tensor) -> Parameterisation:
        """The parameterisation of some rows of the batch (the same here: nothing per row)."""
        return self

    def size(self, n_asperities: int) -> int:
        """D, the number of unbounded parameters of an N-asperity design."""
        return n_asperities - 1 if self.fixed_gamma is not None else 2 * n_asperities - 1

    def to_design(
        self, raw: Tensor, settings: CellSettings, *, sort: bool = True
    ) -> tuple[Tensor, Tensor]:
        """(B, D) -> (gamma, h) (B, N), sorted by height with each gamma kept with its h.

        The losses skip the sort (``sort=False``) where the model does not place asperities
        (a sum over independent ones does not depend on their order)."""
        gamma, h, _ = self.to_design_pullback(raw, settings)
        if not sort:
            return gamma, h
        h, order = torch.sort(h, dim=-1)
        return gamma.gather(-1, order), h

    def to_design_pullback(
        self, raw: Tensor, settings: CellSettings
    ) -> tuple[Tensor, Tensor, Callable[[Tensor, Tensor], Tensor]]:
        """(B, D) -> (gamma, h) (B, N) unsorted, and the pullback ``back(g_gamma, g_h)`` ->
        the gradient (B, D) of ``raw`` for gradients (B, N) of gamma and h (the map's
        derivatives by hand: a closed-form loss needs no autograd, ``physics.tape``)."""
        n = settings.n_asperities
        span = settings.gamma_max - settings.gamma_min
        if self.fixed_gamma is not None:
            u, r_h = None, raw
            gamma = torch.full(
                (raw.shape[0], n), float(self.fixed_gamma), dtype=raw.dtype, device=raw.device
            )
        else:
            u, r_h = torch.sigmoid(raw[:, :n]), raw[:, n:]
            gamma = settings.gamma_min + span * u
        gaps = settings.delta_max * nnf.softplus(r_h)
        h = torch.cat([torch.zeros_like(r_h[:, :1]), gaps], dim=-1)

        def back(g_gamma: Tensor, g_h: Tensor) -> Tensor:
            # autograd's own kernels, in its order: the gradient it would give, to the bit
            g_r_h = _softplus_back(g_h[:, 1:] * settings.delta_max, r_h, 1.0, 20.0)
            if u is None:
                return g_r_h
            return torch.cat([_sigmoid_back(g_gamma * span, u), g_r_h], dim=-1)

        return gamma, h, back

    def from_design(self, gamma: Tensor, h: Tensor, settings: CellSettings) -> Tensor:
        """Inverse of :meth:`to_design` for (B, N) designs, ``START_MARGIN`` inside the
        bounds."""
        order = torch.argsort(h, dim=-1)
        gamma, h = gamma.gather(-1, order), h.gather(-1, order)
        h = (h - h[:, :1])[:, 1:] / settings.delta_max
        r_h = torch.log(torch.expm1(h.clamp_min(START_MARGIN)))
        if self.fixed_gamma is not None:
            return r_h.to(DTYPE)
        u = ((gamma - settings.gamma_min) / (settings.gamma_max - settings.gamma_min)).clamp(
            START_MARGIN, 1 - START_MARGIN
        )
        return torch.cat([torch.logit(u), r_h], dim=-1).to(DTYPE)

    def random(self, count: int, settings: CellSettings, generator: torch.Generator):
        """``count`` random designs (gamma, h), each (count, N): gamma uniform in its bounds
        (or fixed), h uniform in [0, Delta_max]; each drawn whole (gamma then h), so the first
        k of K draws are the k draws."""
        n = settings.n_asperities
        u = torch.rand((count, 2 * n), generator=generator, dtype=DTYPE)
        gamma = settings.gamma_min + (settings.gamma_max - settings.gamma_min) * u[:, :n]
        if self.fixed_gamma is not None:
            gamma = torch.full_like(gamma, float(self.fixed_gamma))
        return gamma, settings.delta_max * u[:, n:]


#: gamma and h both free: the paper's design space.
FULL = Parameterisation()
#: The Hertz-only baseline: every asperity a paraboloid (gamma = 2), heights only.
HERTZ = Parameterisation(fixed_gamma=2.0)


@dataclass(frozen=True)
class FixedHeights(Parameterisation):
    """gamma free, every height fixed: the re-refinement of a design whose heights were
    snapped to a printer's layer grid (D = N).

    h: (B, N) the fixed heights [units of R], one row per row of the batch, in the order
    the asperities keep (no re-sorting: the heights do not move, and a placed model keeps
    asperity k in lattice cell k).
    """

    h: Tensor | None = None

    def __post_init__(self) -> None:
        if self.h is None or self.h.dim() != 2:
            raise MetainterfaceError("FixedHeights needs the (B, N) heights")

    def rows(self, index: Tensor) -> FixedHeights:
        return FixedHeights(h=self.h[index])

    def size(self, n_asperities: int) -> int:
        return n_asperities

    def _heights(self, count: int) -> Tensor:
        # the Levenberg-Marquardt Jacobian evaluates each row several times, rows repeated
        # in place (``losses.residuals``): the heights follow
        b = self.h.shape[0]
        return self.h if count == b else self.h.repeat_interleave(count // b, 0)

    def to_design(self, raw, settings, *, sort=True):
        return self.to_design_pullback(raw, settings)[:2]

    def to_design_pullback(self, raw, settings):
        span = settings.gamma_max - settings.gamma_min
        u = torch.sigmoid(raw)
        gamma = settings.gamma_min + span * u

        def back(g_gamma: Tensor, g_h: Tensor) -> Tensor:
            return _sigmoid_back(g_gamma * span, u)

        return gamma, self._heights(raw.shape[0]).to(raw.dtype), back

    def from_design(self, gamma, h, settings):
        u = ((gamma - settings.gamma_min) / (settings.gamma_max - settings.gamma_min)).clamp(
            START_MARGIN, 1 - START_MARGIN
        )
        return torch.logit(u).to(DTYPE)

    def random(self, count, settings, generator):
        raise MetainterfaceError("FixedHeights refines given designs; it draws no starts")


def snap_heights(h: Tensor, step: float) -> Tensor:
    """Heights (B, N) anchored (min -> 0) and rounded to the nearest multiple of ``step``
    [units of R]: a printer's layer grid."""
    h = h - h.min(dim=-1, keepdim=True).values
    return torch.round(h / step) * step
