"""The contact fractions an adhesive cell reaches at each load (issue 38).

As ``physical.reach`` for adhesionless cells, with JKR asperities (``physics.adhesion``):
one asperity of shape gamma, on the loading branch, carries any force from F(a0) < 0 (just
snapped in, zero indentation) up to its force at Delta_max, with the area pi a(F)^2 of the
JKR branch (F grows with a there); an idle asperity carries 0 with no area. The cell's
least and most area at a total force are the N-fold min-plus and max-plus convolutions of
the one-asperity bounds on a force grid that holds 0 exactly and starts below it.
"""

from __future__ import annotations

import functools
import math

import numpy as np
import torch

from metainterface.physics.cell import CellSettings
from metainterface.physics.jkr import jkr_force, jkr_radius, touch_radius
from metainterface.units._convolution import FORCE_SAMPLES, GAMMA_SAMPLES, _convolve

#: Contact radii sampled per gamma along the loading branch, a0 to a(Delta_max).
RADIUS_SAMPLES = 1024


@functools.lru_cache(maxsize=8)
def adhesive_envelope(
    s: CellSettings, adhesion: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(F, least area, most area) of a whole adhesive cell on a uniform force grid
    [E* R^2 units; F may start below 0]; adhesion w [E* R]."""
    g = torch.linspace(s.gamma_min, s.gamma_max, GAMMA_SAMPLES, dtype=torch.float64)
    a0 = touch_radius(g, adhesion, s.radius)
    top = jkr_radius(g, torch.full_like(g, s.delta_max), adhesion, s.radius)
    t = torch.linspace(0.0, 1.0, RADIUS_SAMPLES, dtype=torch.float64)
    a = a0[:, None] + (top - a0)[:, None] * t[None]  # (G, A)
    f = jkr_force(g[:, None], a, adhesion, s.radius).numpy()
    a = a.numpy()
    f_min, f_max = float(f[:, 0].min()), float(f[:, -1].max())
    step = (f_max - f_min) / FORCE_SAMPLES
    k0 = math.ceil(-f_min / step)
    grid = (np.arange(k0 + math.ceil(f_max / step) + 1) - k0) * step
    low = np.full(grid.size, np.inf)
    high = np.full(grid.size, -np.inf)
    for fi, ai in zip(f, a, strict=True):  # setup, cached: one pass per sampled gamma
        ok = (grid >= fi[0]) & (grid <= fi[-1])
        area = math.pi * np.interp(grid, fi, ai) ** 2
        low = np.where(ok, np.minimum(low, area), low)
        high = np.where(ok, np.maximum(high, area), high)
    low[k0] = min(low[k0], 0.0)  # idle: no force, no area
    high[k0] = max(high[k0], 0.0)
    lo_n, hi_n = low, high
    for _ in range(s.n_asperities - 1):
        lo_n = _convolve(lo_n, low, np.minimum)
        hi_n = _convolve(hi_n, high, np.maximum)
    force = (np.arange(lo_n.size) - s.n_asperities * k0) * step
    return force, lo_n, hi_n
