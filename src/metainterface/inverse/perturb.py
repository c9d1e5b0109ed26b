"""The manufacturing error model: perturbed copies of designs (tolerance, robust design).

For a design (gamma, h) (N,) and standard normals z = (z_gamma, z_h, z_s) of each sample:

    gamma' = max(gamma + sigma_gamma z_gamma, GAMMA_FLOOR)   (clipped: gamma must stay > 1)
    h'     = (1 + scale_sigma z_s) h + sigma_h z_h            (the model anchors min h' -> 0)

with sigma_h in units of R. Made cells are evaluated on :func:`loaded` settings: loaded
past Delta_max where they need it to reach the design's pressures. The same normals serve
every design of a batch (common random numbers): differences between designs are then not
noise of the draws.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import torch
from torch import Tensor

from metainterface.inverse.params import DTYPE
from metainterface.physics.cell import CellSettings

#: Smallest shape exponent of a made asperity: sampled gammas below it are clipped to it
#: (gamma <= 1 has no Sneddon solution; 1.01 is an almost conical tip).
GAMMA_FLOOR = 1.01
#: Made cells are loaded up to this many times Delta_max where they need it to reach a
#: pressure: a cell made with other heights reaches the design's loads at another Delta,
#: and Delta_max bounds the design space, not the part.
REACH = 2.0


@dataclass(frozen=True)
class Perturbation:
    """The error model: standard deviations and the standard normals of each sample.

    sigma_h: height error [units of R]; sigma_gamma: shape-exponent error (absolute);
    scale_sigma: relative error of a common scale of the height offsets. z: (S, 2N + 1)
    standard normals, columns (z_gamma (N), z_h (N), z_s).
    """

    sigma_h: float
    sigma_gamma: float
    scale_sigma: float
    z: Tensor

    @classmethod
    def draw(
        cls,
        n_asperities: int,
        samples: int,
        seed: int,
        *,
        sigma_h: float,
        sigma_gamma: float,
        scale_sigma: float = 0.0,
    ) -> Perturbation:
        """``samples`` seeded draws for an N-asperity design (torch's CPU generator, float64)."""
        gen = torch.Generator().manual_seed(seed)
        z = torch.randn((samples, 2 * n_asperities + 1), generator=gen, dtype=DTYPE)
        return cls(sigma_h, sigma_gamma, scale_sigma, z)

    @property
    def samples(self) -> int:
        return self.z.shape[0]

    def to(self, device: torch.device) -> Perturbation:
        """The same draws on ``device`` (they are always drawn on the CPU: the same seed gives
        the same made cells on every device)."""
        return Perturbation(self.sigma_h, self.sigma_gamma, self.scale_sigma, self.z.to(device))

    def scales(self, n: int) -> Tensor:
        """(2N + 1,) the standard deviation of each column of ``z`` (on its device)."""
        return torch.tensor(
            [self.sigma_gamma] * n + [self.sigma_h] * n + [self.scale_sigma],
            dtype=DTYPE,
            device=self.z.device,
        )

    def apply(self, gamma: Tensor, h: Tensor, *, clip: bool = True) -> tuple[Tensor, Tensor]:
        """Perturbed copies of (B, N) designs: (B S, N) each, design b's copies in rows
        b S ... b S + S - 1 (the same normals for every design: common random numbers)."""
        n = gamma.shape[-1]
        z = self.z.to(dtype=gamma.dtype, device=gamma.device)
        g = gamma[:, None, :] + self.sigma_gamma * z[None, :, :n]
        if clip:
            g = g.clamp_min(GAMMA_FLOOR)
        scale = 1.0 + self.scale_sigma * z[None, :, 2 * n :]
        hh = h[:, None, :] * scale + self.sigma_h * z[None, :, n : 2 * n]
        return g.reshape(-1, n), hh.reshape(-1, n)

    def clipped(self, gamma: Tensor) -> float:
        """The fraction of sampled gammas of the (1, N) design that were clipped."""
        n = gamma.shape[-1]
        raw = gamma + self.sigma_gamma * self.z[:, :n].to(dtype=gamma.dtype, device=gamma.device)
        return float((raw < GAMMA_FLOOR).to(DTYPE).mean())


@functools.lru_cache(maxsize=16)
def loaded(settings: CellSettings, factor: float = REACH) -> CellSettings:
    """The same cell (its a_max, side and nominal area kept) swept to factor * Delta_max.

    The cell's geometry follows from Delta_max (a_max is reached there), so a plain copy
    with a larger Delta_max would be another, larger cell; the geometry is carried over."""
    wide = settings.with_(delta_max=factor * settings.delta_max)
    for name in ("a_max", "cell_side", "nominal_area"):  # cached properties
        wide.__dict__[name] = getattr(settings, name)
    return wide
