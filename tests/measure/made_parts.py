"""Scans of made parts with known errors, written from the closed form of the profile.

A made cell's asperity k is z = -(h_k + r^gamma_k / (2 R^(gamma_k - 1))) in its lattice
square (tips up, lengths in units of R), optionally with a rounded tip: within r0 of the
tip a sphere cap of radius rho, z = z_tip - r^2 / (2 rho), its rim at the profile's height
at r0. The lattice is rotated by theta about the scan's origin, offset, scaled by the
print's shrinkage; a tilt plane, Gaussian noise and missing points are added. Nothing here
uses the package's surface code: it is the reference the fit is held against.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

import metainterface as mi


@dataclass
class Made:
    """How a part came out: exponent shift, height scale, per-asperity height bias [R]."""

    gamma_shift: float = 0.0
    h_scale: float = 1.0
    h_bias: np.ndarray | None = None
    tip_rho: float | None = None  # rounded tips: cap radius [R] within tip_r0
    tip_r0: float = 0.0
    extra: dict = field(default_factory=dict)

    def params(self, design: mi.Design) -> tuple[np.ndarray, np.ndarray]:
        """The made (gamma, h) [h in units of R, min of the design's at 0]."""
        h = self.h_scale * (design.h - design.h.min())
        if self.h_bias is not None:
            h = h + self.h_bias
        return design.gamma + self.gamma_shift, h


def made_cell(u: np.ndarray, v: np.ndarray, design: mi.Design, made: Made) -> np.ndarray:
    """Heights [R] of the made part at cell coordinates (u, v) [R] (periodic)."""
    s = design.settings
    n, side = s.n_side, s.cell_side
    p = side / n
    gamma, h = made.params(design)
    col = np.floor(u / p).astype(int)
    row = np.floor(v / p).astype(int)
    k = (row % n) * n + col % n
    r = np.hypot(u - (col + 0.5) * p, v - (row + 0.5) * p)
    g = gamma[k]
    z = -(h[k] + r**g / (2 * s.radius ** (g - 1)))
    if made.tip_rho is not None:
        r0 = made.tip_r0
        rim = -(h[k] + r0**g / (2 * s.radius ** (g - 1)))
        cap = rim + (r0**2 - r**2) / (2 * made.tip_rho)
        z = np.where(r < r0, cap, z)
    return z


def scan_of(
    design: mi.Design,
    made: Made,
    *,
    cells: float = 3.0,
    points: int = 192,
    theta_deg: float = 0.0,
    offset: tuple[float, float] = (0.13, 0.29),
    shrink: float = 1.0,
    tilt: tuple[float, float] = (0.0, 0.0),
    noise: float = 0.0,
    missing: float = 0.0,
    seed: int = 0,
) -> tuple[np.ndarray, float]:
    """A square scan ``cells`` unit cells wide on points x points: (heights (ny, nx) [R],
    pixel size [R]). offset: the cell corner's position in the scan, in cell sides."""
    side = design.settings.cell_side
    width = cells * side
    dx = width / points
    x, y = np.meshgrid(np.arange(points) * dx, np.arange(points) * dx)
    t = math.radians(theta_deg)
    ox, oy = offset[0] * side, offset[1] * side
    u = (math.cos(t) * (x - ox) + math.sin(t) * (y - oy)) / shrink
    v = (-math.sin(t) * (x - ox) + math.cos(t) * (y - oy)) / shrink
    z = made_cell(u, v, design, made) + tilt[0] * x + tilt[1] * y + 0.123
    rng = np.random.default_rng(seed)
    if noise:
        z = z + rng.normal(0.0, noise, z.shape)
    if missing:
        z[rng.random(z.shape) < missing] = np.nan
    return z, dx


def example(target: bool = True) -> mi.Design:
    """The package's example design, with its own model curve as its target."""
    from importlib.resources import files

    d = mi.Design.load(files("metainterface") / "examples" / "example_design.json")
    if target:
        c = mi.curve(d)
        d = mi.Design(
            gamma=d.gamma,
            h=d.h,
            settings=d.settings,
            extras={**d.extras, "target": {"p_star": list(c.p_star), "alpha": list(c.alpha)}},
        )
    return d
