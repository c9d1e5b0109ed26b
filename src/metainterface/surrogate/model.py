"""The inverse MLP of the paper (sec. 3, appendix A.1, table A.1).

Input: the flattened normalised curve (alpha_hat, S_hat) on n_steps pressures plus
[log10 P*_max, log10 alpha_max] (2 n_steps + 2 values); a network for adhesive targets may
also read log10 of the work of adhesion w / (E* R) (``adhesion_input``, one more value).
Output: 2N sigmoids mapped to gamma_i = gamma_min + (gamma_max - gamma_min) y_i and to
heights through gaps g_1 = 0, g_j = y_j G, h = cumsum(g), sorted by construction.

The gap scale G is the one deliberate departure from the paper. The paper's G = 2 Delta_max
/ (N - 1) (0.25 Delta_max for N = 9) caps h_k at (k - 1) G, so a cell whose second asperity
sits beyond Delta_max cannot be expressed at all. Every test design of the truncated,
stratified and bimodal categories has a gap above that cap
(benchmarks/surrogate_diagnostics.py measures what clipping does to their curves;
MODEL_CARD.md what it does to the network). G = 1.1 Delta_max reaches every design of the
six categories (a gap of Delta_max already switches all later asperities off) at the price
of a coarser output scale for small gaps.
``max_gap`` sets G in units of Delta_max; None gives the paper's value.
"""

from __future__ import annotations

import torch
from torch import Tensor, nn

from metainterface.errors import MetainterfaceError
from metainterface.physics.cell import CellSettings

HIDDEN = (512, 256, 128)
DROPOUT = 0.1
MAX_GAP = 1.1  # default gap scale G / Delta_max of new models (see the module docstring)
#: Training-set spread below which an input counts as constant (for exact curves:
#: alpha_hat at both ends, S_hat at P* = 0).
CONSTANT_STD = 1e-4


def check_max_gap(max_gap: float | None) -> float | None:
    """The gap scale G / Delta_max if it is None or in (0, 10]; a MetainterfaceError if not."""
    if max_gap is not None and not (0 < max_gap <= 10):
        raise MetainterfaceError(f"max_gap must be in (0, 10] (units of Delta_max), got {max_gap}")
    return max_gap


class Dropout(nn.Module):
    """Inverted dropout (as nn.Dropout) whose mask comes from 16-bit random numbers.

    nn.Dropout draws one Bernoulli variate per element, a visible share of a training step;
    one 64-bit draw gives four 16-bit uniforms, four times fewer calls to the generator.
    The drop probability is rounded to a multiple of 2^-16 (0.1 -> 0.100006).
    """

    def __init__(self, p: float) -> None:
        super().__init__()
        if not 0 <= p < 1:
            raise ValueError(f"dropout probability must be in [0, 1), got {p}")
        self.p = p
        self._threshold = round(p * 65536) - 32768  # keep int16 values >= this

    def forward(self, x: Tensor) -> Tensor:
        if not self.training or self.p == 0:
            return x
        n = x.numel()
        words = torch.randint(-(2**63), 2**63 - 1, ((n + 3) // 4,), device=x.device)
        keep = words.view(torch.int16)[:n].view(x.shape) >= self._threshold
        return x * keep * (1.0 / (1.0 - self.p))


class InverseMLP(nn.Module):
    """Curve features (B, 2 n_steps + 2) -> raw outputs y in [0, 1]^(2N).

    With ``adhesion_input`` the features carry one more column, log10(w / (E* R))
    (:func:`adhesion_column`).

    The input is standardised by fixed buffers (set from the training split with
    :meth:`set_input_scaling`; identity by default), then Linear 512 + BatchNorm + GELU +
    Dropout, Linear 256 + BatchNorm + GELU + Dropout, Linear 128 + BatchNorm + GELU,
    Linear 2N + sigmoid.
    """

    def __init__(
        self,
        n_asperities: int = 9,
        n_steps: int = 128,
        max_gap: float | None = MAX_GAP,
        adhesion_input: bool = False,
    ) -> None:
        super().__init__()
        check_max_gap(max_gap)
        self.n_asperities = n_asperities
        self.n_steps = n_steps
        self.max_gap = max_gap
        self.adhesion_input = bool(adhesion_input)
        n_in = 2 * n_steps + 2 + int(self.adhesion_input)
        layers: list[nn.Module] = []
        width = n_in
        for i, hidden in enumerate(HIDDEN):
            layers += [nn.Linear(width, hidden), nn.BatchNorm1d(hidden), nn.GELU()]
            if i < len(HIDDEN) - 1:
                layers.append(Dropout(DROPOUT))
            width = hidden
        layers += [nn.Linear(width, 2 * n_asperities), nn.Sigmoid()]
        self.net = nn.Sequential(*layers)
        self.register_buffer("in_mean", torch.zeros(n_in))
        self.register_buffer("in_std", torch.ones(n_in))

    def set_input_scaling(self, features: Tensor) -> None:
        """Standardise inputs by the mean and std of ``features`` (B, 2 n_steps + 2)."""
        self.in_mean.copy_(features.mean(0))
        self.in_std.copy_(features.std(0).clamp_min(1e-6))

    def constant_inputs(self) -> Tensor:
        """(2 n_steps + 2,) bool: the inputs that did not vary where the network was trained
        (spread below CONSTANT_STD); it learned nothing from them."""
        return self.in_std < CONSTANT_STD

    def forward(self, features: Tensor) -> Tensor:
        return self.net((features - self.in_mean) / self.in_std)

    def architecture(self) -> dict[str, int | float | bool | None]:
        """The constructor arguments, JSON-ready (stored in model files)."""
        return {
            "n_asperities": self.n_asperities,
            "n_steps": self.n_steps,
            "max_gap": self.max_gap,
            "adhesion_input": self.adhesion_input,
        }

    def design(self, features: Tensor, settings: CellSettings) -> tuple[Tensor, Tensor]:
        """Curve features (B, 2 n_steps + 2) -> predicted (gamma, h), each (B, N)."""
        return outputs_to_design(self(features), settings, self.max_gap)


def adhesion_column(w: Tensor) -> Tensor:
    """The input column of a network that reads adhesion: log10 of w / (E* R), (B,) -> (B, 1),
    floored at 1e-12 (no adhesion reads as very little)."""
    return torch.log10(w.clamp_min(1e-12))[:, None]


def outputs_to_design(
    y: Tensor, settings: CellSettings, max_gap: float | None = MAX_GAP
) -> tuple[Tensor, Tensor]:
    """Map raw outputs y (B, 2N) in [0, 1] to (gamma, h), each (B, N); h sorted, h_1 = 0.

    max_gap: the gap scale G in units of Delta_max; None for the paper's 2 / (N - 1).
    """
    n = settings.n_asperities
    y_gamma, y_gap = y[:, :n], y[:, n:]
    gamma = settings.gamma_min + (settings.gamma_max - settings.gamma_min) * y_gamma
    if max_gap is None:
        step = 2.0 * settings.delta_max / max(n - 1, 1)
    else:
        step = max_gap * settings.delta_max
    gaps = torch.cat([torch.zeros_like(y_gap[:, :1]), y_gap[:, 1:] * step], dim=-1)
    return gamma, torch.cumsum(gaps, dim=-1)
