"""What the power-law family cannot describe, read from the measured cell, and the cell
restored before the BEM: the scan's noise floor, a printer's layer steps (terraces), flat
tips, missing or extra material.

- **Noise floor**: the scan's pixel noise, from the median absolute fourth difference
  along the rows and the columns (blind to the surface's curvature; robust to steps and
  edges where they are a minority of the points).
  The measured cell averages the copies of the cell the scan shows, so its noise is lower.
- **Terraces**: a layered print puts every height on a level ``phase + k step``. Among the
  flattest points of the cell's top (those whose 3 x 3 neighbourhood spans the least: the
  treads, not the blurred risers), the share of heights on such levels is the modulus of
  mean(exp(2 pi i z / step)); the largest step where it peaks above ``MIN_COHERENCE`` is
  the layer step, its argument the phase. A scan's pixels blur a riser narrower than a few
  of them into a ramp; every height is put back on its nearest level (the riser then sits
  where the ramp crosses mid-level, where it was), which also takes the noise off.
- **Flat tips**: the top of each asperity that stays within the noise of its highest point,
  where the fitted power law would leave a much smaller one; its radius is reported and
  its plateau made flat (noise off where the first contact forms).
- **Missing or extra material**: where the measured cell lies further from the fitted
  asperity than a third of Delta_max.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from metainterface.measure.scan import Scan
from metainterface.physics.cell import Design

#: Smallest layer-level coherence that counts as terraces (a smooth surface reads < 0.2).
MIN_COHERENCE = 0.5
#: Share of the top's points, the flattest, on which terraces are looked for.
TREAD_SHARE = 0.3
#: Smallest layer step looked for [units of Delta_max]: finer ones would be a tenth of the
#: design's height range, and a design's own offsets on a round grid read as such steps.
MIN_STEP = 0.1
#: Smallest levels' coherence on the asperities' flanks, below their top level: layers show
#: there too (0.40-0.98 on the tuning prints), a few flat tops at round heights do not
#: (0.05-0.16).
MIN_FLANK_COHERENCE = 0.3
#: Fewest tread points below an asperity's top level for its flank to count.
MIN_LEVEL_POINTS = 20
#: Fewest tread points to read layers from.
MIN_TREAD_POINTS = 200
#: Depth of the top looked at [units of Delta_max]: where contact happens.
TOP_DEPTH = 2.0
#: Cell noise [units of Delta_max] below which the measured cell is left as it is: 0.02 um
#: of cell noise at R = 0.5 mm read the first contacts' area 2.5 % low against the exact
#: cell (benchmarks/bench_measure.py); the Gaussian that takes it off is at most one grid
#: step, half a scan pixel at the default grid, so nothing the scan resolves is lost.
NOISE_TOLERANCE = 0.0005
#: A flat tip: its plateau's radius at least this many scan pixels, and this many times the
#: fitted power law's own within the same height band.
FLAT_PIXELS = 2.0
FLAT_RATIO = 1.4
#: Material further than this from the fitted asperity [units of Delta_max] is reported.
FEATURE_DEPTH = 1.0 / 3.0
#: The bilinear read's share of a pixel's noise (sum of the squared weights, on average
#: (2/3)^2, square-rooted).
BILINEAR_NOISE = 2.0 / 3.0


@dataclass(frozen=True)
class Terraces:
    """Layer levels phase + k step [units of R] in the registration's height frame (made
    tips at -h); coherence: the share of the treads' heights on them (0 to 1)."""

    step: float
    phase: float
    coherence: float
    given: bool = False


@dataclass(frozen=True)
class Shapes:
    """What the scan shows beyond the fitted family.

    noise: the scan's pixel noise [R]; cell_noise: the measured cell's [R], before any
    restoration; terraces: the layer levels or None; flat_radius: (N,) each asperity's flat
    top radius [R] (0: none); plateau: (N,) its height [R] (the registration's frame);
    feature: (N,) '' or 'missing material' / 'extra material'; smoothed: the Gaussian
    applied to the cell [grid steps] where noise had to be taken off without terraces."""

    noise: float
    cell_noise: float
    terraces: Terraces | None
    flat_radius: np.ndarray
    plateau: np.ndarray
    feature: list[str]
    smoothed: float = 0.0

    def restored(self) -> list[str]:
        """What was restored in the measured cell before the BEM, in words."""
        out = []
        if self.terraces is not None:
            out.append(
                "heights put back on the layer levels (step "
                f"{'given' if self.terraces.given else 'read from the scan'})"
            )
        if np.any(self.flat_radius > 0):
            out.append("flat tips made flat at their plateau")
        if self.smoothed > 0:
            out.append(f"noise off by a Gaussian of {self.smoothed:.2g} grid steps")
        return out


def noise_floor(scan: Scan) -> float:
    """The scan's pixel noise [R]: 1.4826 MAD of the fourth differences along x and y,
    over sqrt(70) (white noise's share in them). A fourth difference leaves out the
    surface's own curvature, which at a coarse pixel is as large as the noise; a layer step
    is an outlier the median passes over, unless the risers are most of the points (a
    densely terraced scan with pixels wider than its treads): it then reads high."""
    z = scan.heights
    parts = []
    for a in (z, z.T):
        d = a[:, :-4] - 4 * a[:, 1:-3] + 6 * a[:, 2:-2] - 4 * a[:, 3:-1] + a[:, 4:]
        parts.append(d[np.isfinite(d)])
    d = np.concatenate(parts)
    if d.size < 16:
        return 0.0
    mad = np.median(np.abs(d - np.median(d)))
    return float(1.4826 * mad / math.sqrt(70.0))


def find_terraces(
    cell: np.ndarray,
    noise: float,
    delta_max: float,
    step: float | None = None,
    owner: np.ndarray | None = None,
) -> Terraces | None:
    """Layer levels of a measured cell (M, M) [R] (module docstring), or None. step: the
    layer step when known (``--z-step``): only its phase is read. owner: (M, M) asperity
    index: the levels must show on most asperities' flanks too, below their top level, with
    a coherence of ``MIN_FLANK_COHERENCE`` (a few flat tops at round heights are no
    layers)."""
    from scipy import ndimage

    def spread(z: np.ndarray) -> np.ndarray:
        return ndimage.maximum_filter(z, 3, mode="wrap") - ndimage.minimum_filter(z, 3, mode="wrap")

    top = cell > cell.max() - TOP_DEPTH * delta_max
    mine = spread(cell)
    flat = top & (mine <= np.quantile(mine[top], TREAD_SHARE))
    if flat.sum() < MIN_TREAD_POINTS:
        return None if step is None else Terraces(step, 0.0, 0.0, given=True)
    owner_flat = None if owner is None else owner[flat]
    z = cell[flat]
    if z.size > 40_000:
        z = z[:: math.ceil(z.size / 40_000)]
    span = float(z.max() - z.min())
    if span <= 0:
        return None

    def coherence(f: np.ndarray) -> np.ndarray:
        return np.exp(2j * np.pi * f[:, None] * z[None]).mean(axis=1)

    if step is not None:
        c = coherence(np.array([1.0 / step]))[0]
        return Terraces(step, _phase(c, step), float(abs(c)), given=True)
    # frequencies from 4 levels over the top to ten noise widths a level; steps of a tenth
    # of the peak's width (1 / span)
    f_lo = 4.0 / span
    f_hi = 1.0 / max(10.0 * noise, MIN_STEP * delta_max)
    if f_hi <= f_lo:
        return None
    f = np.arange(f_lo, f_hi, 0.1 / span)
    c = np.abs(coherence(f))
    best = float(c.max())
    if best < MIN_COHERENCE:
        return None
    # the largest step of the peaks (a step's halves, thirds, ... are on its levels too)
    f0 = float(f[c >= 0.9 * best].min())
    fine = np.linspace(f0 - 0.1 / span, f0 + 0.1 / span, 41)
    cf = coherence(fine)
    i = int(np.argmax(np.abs(cf)))
    step = 1.0 / float(fine[i])
    phase = _phase(cf[i], step)
    # the peak's place is blurred by the risers' points; the levels themselves are not:
    # each tread point's level index, then z = phase + k step by least squares (twice)
    for _ in range(2):
        k = np.round((z - phase) / step)
        near = np.abs(z - phase - k * step) < 0.25 * step
        if np.ptp(k[near]) < 2:
            break
        a = np.stack([np.ones(near.sum()), k[near]], axis=1)
        (phase, step), *_ = np.linalg.lstsq(a, z[near], rcond=None)
        phase = float(phase) % float(step)
    c = coherence(np.array([1.0 / step]))[0]
    terraces = Terraces(float(step), _phase(c, float(step)), float(abs(c)))
    if (
        owner_flat is not None
        and _flank_coherence(cell[flat], owner_flat, terraces) < MIN_FLANK_COHERENCE
    ):
        return None
    return terraces


def _flank_coherence(z: np.ndarray, owner: np.ndarray, t: Terraces) -> float:
    """The median over the asperities of the levels' coherence on their tread points below
    their top level (a flat or top tread left out: a few tops at round heights would look
    like layers; real layers show on the flanks too)."""
    values = []
    for a in np.unique(owner):
        za = z[owner == a]
        k = np.round((za - t.phase) / t.step)
        below = za[k < k.max()]
        if below.size >= MIN_LEVEL_POINTS:
            values.append(abs(np.exp(2j * np.pi * below / t.step).mean()))
    return float(np.median(values)) if values else 0.0


def _phase(c: complex, step: float) -> float:
    return float(np.angle(c) / (2 * np.pi) * step) % step


def on_levels(z: np.ndarray, t: Terraces) -> np.ndarray:
    """Heights put on their nearest layer level."""
    return t.phase + t.step * np.round((z - t.phase) / t.step)


def analyse(
    cell: np.ndarray,
    fitted: np.ndarray,
    owner: np.ndarray,
    scan: Scan,
    copies: np.ndarray,
    design: Design,
    gamma: np.ndarray,
    z_step: float | None = None,
) -> Shapes:
    """The shapes of a measured cell (M, M) [R] against the fitted family's (M, M), with
    ``owner`` (M, M) the asperity index of each point and ``copies`` (M, M) the scan's
    copies averaged there; gamma (N,): the fitted exponents; z_step [R]: a known layer."""
    s = design.settings
    noise = noise_floor(scan)
    cell_noise = BILINEAR_NOISE * noise * float(np.sqrt(np.mean(1.0 / np.maximum(copies, 1))))
    n = s.n_asperities
    noise_band = max(3.0 * cell_noise, 1e-4 * s.delta_max)
    terraces = find_terraces(cell, cell_noise, s.delta_max, z_step, owner)
    work = on_levels(cell, terraces) if terraces is not None else cell
    m = cell.shape[0]
    spacing = s.cell_side / m
    pixel = max(scan.dx, scan.dy)
    band = noise_band if terraces is None else 1e-9
    flat_radius, plateau = np.zeros(n), np.full(n, np.nan)
    feature = [""] * n
    from scipy import ndimage

    from metainterface.physics.sneddon import shape_constant

    c = shape_constant(np.asarray(gamma, dtype=np.float64), s.radius)
    for k in range(n):
        mine = owner == k
        region, top = _plateau(work, mine, band)
        area = float(region.sum()) * spacing**2
        radius = math.sqrt(area / math.pi)
        own = (band / c[k]) ** (1.0 / gamma[k]) + spacing
        if radius > max(FLAT_PIXELS * pixel, FLAT_RATIO * own):
            flat_radius[k], plateau[k] = radius, top
        # material off the fitted shape, outside a flat top (a cut tip is reported as one)
        # and beyond half a layer (the steps' own)
        body = mine & (fitted > fitted[mine].max() - s.delta_max)
        if flat_radius[k] > 0:
            body &= ~ndimage.binary_dilation(region, iterations=2)
        depth = FEATURE_DEPTH * s.delta_max + (0.5 * terraces.step if terraces else 0.0)
        diff = np.where(body, work - fitted, 0.0)
        if diff.max() > depth:
            feature[k] = "extra material"
        elif diff.min() < -depth:
            feature[k] = "missing material"
    smoothed = 0.0
    tolerance = NOISE_TOLERANCE * s.delta_max
    if terraces is None and cell_noise > tolerance:
        # a Gaussian of sigma s steps divides white noise by 2 sqrt(pi) s
        smoothed = float(min(1.0, cell_noise / (tolerance * 2.0 * math.sqrt(math.pi))))
    return Shapes(
        noise=noise,
        cell_noise=cell_noise,
        terraces=terraces,
        flat_radius=flat_radius,
        plateau=plateau,
        feature=feature,
        smoothed=smoothed,
    )


def _plateau(z: np.ndarray, mine: np.ndarray, band: float) -> tuple[np.ndarray, float]:
    """The points of ``mine`` connected to its highest that lie within ``band`` of it, and
    that height, both read on z's 3 x 3 median (a noise spike is no top)."""
    from scipy import ndimage

    zs = ndimage.median_filter(z, 3, mode="wrap")
    zk = np.where(mine, zs, -np.inf)
    peak = np.unravel_index(int(np.argmax(zk)), zk.shape)
    top = float(zk[peak])
    lab, _ = ndimage.label(zk >= top - band)
    return lab == lab[peak], top


def restore(cell: np.ndarray, owner: np.ndarray, shapes: Shapes) -> np.ndarray:
    """The measured cell (M, M) [R] as the BEM sees it: heights on their layer levels,
    flat tips flat at their plateau, or (no terraces) the noise smoothed off as ``shapes``
    says."""
    out = cell
    if shapes.terraces is not None:
        out = on_levels(out, shapes.terraces)
    elif shapes.smoothed > 0:
        from scipy import ndimage

        out = ndimage.gaussian_filter(out, shapes.smoothed, mode="wrap")
    flat = shapes.flat_radius > 0
    if flat.any():
        cap = np.where(flat, shapes.plateau, np.inf)[owner]
        out = np.minimum(out, cap)
    return out
