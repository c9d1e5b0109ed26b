"""The inverse MLP of the paper (sec. 3, appendix A.1, table A.1).

Input: the flattened normalised curve (alpha_hat, S_hat) on n_steps pressures plus
[log10 P*_max, log10 alpha_max] (2 n_steps + 2 values). Output: 2N sigmoids mapped to
gamma_i = gamma_min + (gamma_max - gamma_min) y_i and to heights through gaps
g_1 = 0, g_j = y_j 2 Delta_max / (N - 1), h = cumsum(g), sorted by construction.
"""

from __future__ import annotations

import torch
from torch import Tensor, nn

from metainterface.physics.cell import CellSettings

HIDDEN = (512, 256, 128)
DROPOUT = 0.1


class InverseMLP(nn.Module):
    """Curve features (B, 2 n_steps + 2) -> raw outputs y in [0, 1]^(2N).

    The input is standardised by fixed buffers (set from the training split with
    :meth:`set_input_scaling`; identity by default), then Linear 512 + BatchNorm + GELU +
    Dropout, Linear 256 + BatchNorm + GELU + Dropout, Linear 128 + BatchNorm + GELU,
    Linear 2N + sigmoid.
    """

    def __init__(self, n_asperities: int = 9, n_steps: int = 128) -> None:
        super().__init__()
        self.n_asperities = n_asperities
        self.n_steps = n_steps
        n_in = 2 * n_steps + 2
        layers: list[nn.Module] = []
        width = n_in
        for i, hidden in enumerate(HIDDEN):
            layers += [nn.Linear(width, hidden), nn.BatchNorm1d(hidden), nn.GELU()]
            if i < len(HIDDEN) - 1:
                layers.append(nn.Dropout(DROPOUT))
            width = hidden
        layers += [nn.Linear(width, 2 * n_asperities), nn.Sigmoid()]
        self.net = nn.Sequential(*layers)
        self.register_buffer("in_mean", torch.zeros(n_in))
        self.register_buffer("in_std", torch.ones(n_in))

    def set_input_scaling(self, features: Tensor) -> None:
        """Standardise inputs by the mean and std of ``features`` (B, 2 n_steps + 2)."""
        self.in_mean.copy_(features.mean(0))
        self.in_std.copy_(features.std(0).clamp_min(1e-6))

    def forward(self, features: Tensor) -> Tensor:
        return self.net((features - self.in_mean) / self.in_std)


def outputs_to_design(y: Tensor, settings: CellSettings) -> tuple[Tensor, Tensor]:
    """Map raw outputs y (B, 2N) in [0, 1] to (gamma, h), each (B, N); h sorted, h_1 = 0."""
    n = settings.n_asperities
    y_gamma, y_gap = y[:, :n], y[:, n:]
    gamma = settings.gamma_min + (settings.gamma_max - settings.gamma_min) * y_gamma
    step = 2.0 * settings.delta_max / max(n - 1, 1)
    gaps = torch.cat([torch.zeros_like(y_gap[:, :1]), y_gap[:, 1:] * step], dim=-1)
    return gamma, torch.cumsum(gaps, dim=-1)
