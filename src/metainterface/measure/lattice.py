"""Where the design's lattice lies in a scan: period, rotation, offset (registration).

Scan coordinates (x, y) [units of R] map to cell coordinates (u, v) by

    (u, v) = (p_design / p) Rot(-theta) ((x, y) - origin),

origin being the scan position of a unit cell's corner (u = v = 0), theta the lattice's
rotation (a few degrees) and p the measured lattice pitch (the design's p_design = L / n
times a print's shrinkage). A first estimate comes from the asperity tips (local maxima):
their spacings give p and theta, their positions the offset modulo p, and which of the n^2
shifts puts asperity k where the design has it is the one whose designed map, scaled and
tilted (linear least squares), explains the scan best. ``fit.fit_lattice`` then refines the
lattice together with the tilt.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from metainterface.errors import MetainterfaceError
from metainterface.measure.scan import Scan
from metainterface.measure.surface import lattice_surface
from metainterface.physics.cell import Design

#: Largest relative difference between the measured and the designed pitch.
PITCH_TOLERANCE = 0.2
#: Smallest share of the scan's height variance that the designed lattice must explain.
MIN_EXPLAINED = 0.5
#: Points used by the identification's least squares (a random subset of the scan).
SAMPLE_POINTS = 40_000


@dataclass(frozen=True)
class Lattice:
    """The lattice in a scan. origin: (2,) scan position [units of R] of a unit cell's
    corner; theta: rotation [rad]; pitch: measured lattice pitch [units of R]; design_pitch:
    the design's L / n [units of R]."""

    origin: np.ndarray
    theta: float
    pitch: float
    design_pitch: float

    @property
    def scale(self) -> float:
        """Measured over designed pitch (1 - shrinkage)."""
        return self.pitch / self.design_pitch

    def to_cell(self, x: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Scan (x, y) -> cell (u, v) [units of R], any shapes."""
        c, s = math.cos(self.theta), math.sin(self.theta)
        dx, dy = x - self.origin[0], y - self.origin[1]
        k = 1.0 / self.scale
        return k * (c * dx + s * dy), k * (-s * dx + c * dy)

    def to_scan(self, u: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Cell (u, v) -> scan (x, y) [units of R], any shapes."""
        c, s = math.cos(self.theta), math.sin(self.theta)
        k = self.scale
        return (
            self.origin[0] + k * (c * u - s * v),
            self.origin[1] + k * (s * u + c * v),
        )

    def to_dict(self) -> dict[str, float]:
        return {
            "origin_x": float(self.origin[0]),
            "origin_y": float(self.origin[1]),
            "rotation_deg": math.degrees(self.theta),
            "pitch": float(self.pitch),
            "design_pitch": float(self.design_pitch),
            "scale": float(self.scale),
        }


def _plane(scan: Scan) -> np.ndarray:
    x, y = np.meshgrid(*scan.coords())
    ok = scan.valid
    a = np.stack([x[ok], y[ok], np.ones(ok.sum())], axis=1)
    coef, *_ = np.linalg.lstsq(a, scan.heights[ok], rcond=None)
    return coef


def plane_slopes(scan: Scan) -> np.ndarray:
    """(2,) slopes (dz/dx, dz/dy) of the scan's least-squares plane: a first levelling only
    (biased by the pattern; the lattice fit levels it properly)."""
    return _plane(scan)[:2]


def plane_removed(scan: Scan) -> np.ndarray:
    """The scan's heights less their least-squares plane (only to find tips; biased by the
    pattern, so never the levelling itself)."""
    x, y = np.meshgrid(*scan.coords())
    coef = _plane(scan)
    return scan.heights - (coef[0] * x + coef[1] * y + coef[2])


def find_tips(scan: Scan, pitch: float) -> np.ndarray:
    """(T, 2) scan positions (x, y) [units of R] of the local maxima that are highest within
    half a pitch, away from the scan's edges and missing points."""
    from scipy import ndimage

    z = plane_removed(scan)
    low = np.nanmin(z)
    filled = np.where(np.isfinite(z), z, low)
    px = pitch / min(scan.dx, scan.dy)
    # a twelfth of a pitch: the noise off, and a flat or terraced top's highest point at its
    # centre (a flat top's maximum pixel is anywhere on it); a neighbour a pitch away is
    # six sigmas off and does not move it
    sigma = max(1.0, px / 12.0)
    smooth = ndimage.gaussian_filter(filled, sigma, mode="nearest")
    size = max(3, int(0.5 * px) | 1)
    peak = (smooth == ndimage.maximum_filter(smooth, size=size, mode="nearest")) & scan.valid
    edge = max(2, int(0.04 * px))
    peak[:edge], peak[-edge:], peak[:, :edge], peak[:, -edge:] = False, False, False, False
    # a flank cut by missing points is no tip: the window around a tip is mostly measured
    seen = ndimage.uniform_filter(scan.valid.astype(float), size=size, mode="constant")
    peak &= seen > 0.5
    i, j = np.nonzero(peak)
    return np.stack([j * scan.dx, i * scan.dy], axis=1)


def _spacing(tips: np.ndarray, design_pitch: float) -> tuple[float, float] | None:
    """(theta, pitch) from nearest-neighbour vectors between tips, or None if no pair."""
    if len(tips) < 2:
        return None
    d = tips[None] - tips[:, None]
    length = np.hypot(d[..., 0], d[..., 1])
    near = (length > (1 - PITCH_TOLERANCE) * design_pitch) & (
        length < (1 + PITCH_TOLERANCE) * design_pitch
    )
    if not near.any():
        return None
    phi = np.arctan2(d[..., 1][near], d[..., 0][near])
    theta = 0.25 * math.atan2(np.sin(4 * phi).mean(), np.cos(4 * phi).mean())
    return theta, float(np.median(length[near]))


def lattice_geometry(scan: Scan, design_pitch: float) -> tuple[np.ndarray, float, float]:
    """The scan's tips (T, 2), the lattice's rotation theta (modulo 90 degrees: a square
    lattice looks the same turned by a quarter) [rad] and its pitch [R]. Raises
    MetainterfaceError if the scan shows no lattice of this pitch."""
    tips = find_tips(scan, design_pitch)
    if len(tips) == 0:
        raise MetainterfaceError(
            "scan does not show this design's lattice: no asperity tip found "
            f"(pitch {design_pitch * scan.radius_m * 1e6:.4g} um expected)"
        )
    found = _spacing(tips, design_pitch)
    if found is None:
        if len(tips) > 3:
            raise MetainterfaceError(
                "scan does not show this design's lattice: its tips are not "
                f"{design_pitch * scan.radius_m * 1e6:.4g} um apart (within "
                f"{PITCH_TOLERANCE:.0%})"
            )
        return tips, 0.0, design_pitch
    theta, pitch = found
    return tips, theta, pitch


def lattice_at(
    tips: np.ndarray, theta: float, pitch: float, design_pitch: float, shift: tuple[int, int]
) -> Lattice:
    """The lattice turned by ``theta`` whose unit cell's corner is ``shift`` = (columns,
    rows) lattice squares from the one the tips put nearest the scan's origin: each of the
    n^2 shifts puts another asperity of the design on a given tip."""
    c, s = math.cos(theta), math.sin(theta)
    w = np.stack([c * tips[:, 0] + s * tips[:, 1], -s * tips[:, 0] + c * tips[:, 1]], 1) / pitch
    frac = np.angle(np.exp(2j * np.pi * (w - 0.5)).mean(axis=0)) / (2 * np.pi)  # (2,)
    o = pitch * (frac + np.asarray(shift, dtype=np.float64))  # in the turned frame
    origin = np.array([c * o[0] - s * o[1], s * o[0] + c * o[1]])
    return Lattice(origin=origin, theta=theta, pitch=pitch, design_pitch=design_pitch)


def explained(lat: Lattice, design: Design, scan: Scan) -> tuple[float, np.ndarray, float]:
    """Share of the scan's height variance that the designed map (scaled) and a plane
    explain on ``lat``, that plane's slopes (2,) (dz/dx, dz/dy), and the scale of the
    designed map's heights that does it (about 1 for a part as made; 1000 for a height
    unit slip)."""
    return _explained(lat, design, *_sample(scan))


def _sample(scan: Scan) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    ok = np.flatnonzero(scan.valid.ravel())
    if ok.size > SAMPLE_POINTS:
        ok = np.random.default_rng(0).choice(ok, SAMPLE_POINTS, replace=False)
    i, j = np.divmod(ok, scan.shape[1])
    return j * scan.dx, i * scan.dy, scan.heights.ravel()[ok]


def _explained(
    lat: Lattice, design: Design, x: np.ndarray, y: np.ndarray, z: np.ndarray
) -> tuple[float, np.ndarray, float]:
    """Share of var(z) explained by a * designed map + tilt plane (linear least squares),
    that plane's slopes (2,) and a."""
    u, v = lat.to_cell(x, y)
    s = design.settings
    t = lattice_surface(u, v, -(design.h - design.h.min()), design.gamma, s)
    a = np.stack([t, x, y, np.ones_like(x)], axis=1)
    coef, *_ = np.linalg.lstsq(a, z, rcond=None)
    if coef[0] <= 0:
        return 0.0, coef[1:3], float(coef[0])
    res = z - a @ coef
    return float(1.0 - res.var() / max(z.var(), 1e-300)), coef[1:3], float(coef[0])
