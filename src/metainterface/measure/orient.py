"""Which way round the part lies in the scan: the lattice's symmetries tried, one chosen.

A square lattice looks the same turned by a quarter, so its tips give its rotation only
modulo 90 degrees, and a file whose y axis runs the other way (common between instruments)
shows the part mirrored. Every asperity is fitted once, where it sits, before anyone says
which asperity of the design it is; then each of the 8 symmetries of the square (4 turns,
each also mirrored) and each of the n^2 shifts of the unit cell assigns the fitted
asperities to the design's, and the assignment kept is the one under which they match the
design under one common map: the made exponent the designed one plus a shift, the made tip
height a (positive) scale of the designed offset plus a plane. The score is the share of
the fitted exponents' and heights' variation that the map leaves unexplained (0: perfect);
the margin is the next best's score over the best's, and a margin under ``MIN_MARGIN`` says
that two orientations are too close to tell apart.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from metainterface.errors import MetainterfaceError
from metainterface.measure.fit import AsperityFits, fit_asperities
from metainterface.measure.lattice import (
    MIN_EXPLAINED,
    Lattice,
    explained,
    lattice_at,
    lattice_geometry,
    plane_slopes,
)
from metainterface.measure.scan import Scan
from metainterface.physics.cell import Design

#: Next best score over the best one under which two orientations cannot be told apart.
MIN_MARGIN = 2.0
#: Floor of a score (a perfect, noiseless match would divide by zero in the margin).
SCORE_FLOOR = 1e-6
#: A height scale beyond this factor either way is a unit slip, not a part made too tall
#: or too flat (a print's heights are off by tens of percent; a unit by 1000).
SLIP_FACTOR = 30.0


@dataclass(frozen=True)
class Orientation:
    """How the part lies in the scan.

    quarter_turns: 0-3, the quarter turns (counter-clockwise) between the scan's axes and
    the design's, on top of ``Lattice.theta``'s small angle; mirrored: the scan's y axis
    was reversed (the scan registered is the mirrored one); shift: the unit cell's corner
    (columns, rows) in lattice squares; score: the share of the fitted asperities'
    variation the common map leaves unexplained; margin: the next best orientation's score
    over this one's; runner_up: that orientation, in words; ambiguous: margin < MIN_MARGIN;
    height_scale: the scale of the designed map's heights that best explains the scan's
    (about 1 for a part as made; 1000 or 0.001 for a height unit slip).
    """

    quarter_turns: int
    mirrored: bool
    shift: tuple[int, int]
    score: float
    margin: float
    runner_up: str
    ambiguous: bool
    height_scale: float = 1.0

    @property
    def unit_slip(self) -> bool:
        """Whether ``height_scale`` is off by more than ``SLIP_FACTOR`` either way."""
        return not 1 / SLIP_FACTOR < self.height_scale < SLIP_FACTOR

    def describe(self) -> str:
        """The orientation in words, e.g. 'turned 90 degrees, mirrored (y reversed)'."""
        return _words(self.quarter_turns, self.mirrored)

    def to_dict(self) -> dict[str, object]:
        return {
            "quarter_turns": self.quarter_turns,
            "mirrored": self.mirrored,
            "described": self.describe(),
            "shift": list(self.shift),
            "score": self.score,
            "margin": self.margin,
            "runner_up": self.runner_up,
            "ambiguous": self.ambiguous,
            "height_scale": self.height_scale,
        }


def _words(turns: int, mirrored: bool) -> str:
    text = "as designed" if turns == 0 else f"turned {90 * turns} degrees"
    return text + (", mirrored (the file's y axis reversed)" if mirrored else "")


def mirrored(scan: Scan) -> Scan:
    """The scan with its y axis reversed (rows in the other order)."""
    from dataclasses import replace

    return replace(scan, heights=np.ascontiguousarray(scan.heights[::-1]))


@dataclass(frozen=True)
class _Candidate:
    score: float
    turns: int
    mirror: bool
    shift: tuple[int, int]
    lattice: Lattice
    scan: Scan


def orient(
    scan: Scan, design: Design, design_pitch: float
) -> tuple[Scan, Lattice, np.ndarray, float, Orientation]:
    """The scan as registered (mirrored or not), its lattice, the tilt (2,), the share of
    its variance the designed map explains there, and the orientation chosen (module
    docstring). Raises MetainterfaceError if no orientation shows this design's lattice."""
    candidates: list[_Candidate] = []
    for mirror in (False, True):
        seen = mirrored(scan) if mirror else scan
        tips, theta, pitch = lattice_geometry(seen, design_pitch)
        base = lattice_at(tips, theta, pitch, design_pitch, (0, 0))
        tilt = plane_slopes(seen)
        fits = fit_asperities(seen, design, base, tilt, gamma_start=float(np.median(design.gamma)))
        if fits.kind.size == 0:
            continue
        centres = _centres(base, fits)
        for turns in range(4):
            for di in range(design.settings.n_side):
                for dj in range(design.settings.n_side):
                    lat = lattice_at(
                        tips, theta + turns * math.pi / 2, pitch, design_pitch, (dj, di)
                    )
                    kind = _kinds(lat, centres, design)
                    score = _score(fits, centres, kind, design)
                    candidates.append(_Candidate(score, turns, mirror, (dj, di), lat, seen))
    if not candidates:
        raise MetainterfaceError(
            "scan does not show this design's lattice: no asperity is seen whole enough to fit"
        )
    candidates.sort(key=lambda c: c.score)
    best = candidates[0]
    # the runner-up: the best candidate that assigns the asperities otherwise (another
    # turn or mirror, or another shift)
    others = [c for c in candidates[1:] if (c.turns, c.mirror) != (best.turns, best.mirror)]
    runner = others[0] if others else None
    margin = (
        math.inf
        if runner is None
        else max(runner.score, SCORE_FLOOR) / max(best.score, SCORE_FLOOR)
    )
    share, tilt, height_scale = explained(best.lattice, design, best.scan)
    if share < MIN_EXPLAINED:
        raise MetainterfaceError(
            "scan does not show this design's lattice: the designed map explains "
            f"{share:.0%} of its height variance in the best orientation "
            f"({_words(best.turns, best.mirror)}; at least {MIN_EXPLAINED:.0%} expected)"
        )
    orientation = Orientation(
        quarter_turns=best.turns,
        mirrored=best.mirror,
        shift=best.shift,
        score=float(best.score),
        margin=float(margin),
        runner_up="none" if runner is None else _words(runner.turns, runner.mirror),
        ambiguous=bool(margin < MIN_MARGIN),
        height_scale=height_scale,
    )
    return best.scan, best.lattice, tilt, share, orientation


def _centres(lat: Lattice, fits: AsperityFits) -> np.ndarray:
    """(B, 2) scan positions of the fitted asperities' lattice points."""
    p = lat.design_pitch
    x, y = lat.to_scan((fits.cell[:, 0] + 0.5) * p, (fits.cell[:, 1] + 0.5) * p)
    return np.stack([x, y], axis=1)


def _kinds(lat: Lattice, centres: np.ndarray, design: Design) -> np.ndarray:
    """(B,) the design's asperity index at each lattice point under ``lat``."""
    n = design.settings.n_side
    u, v = lat.to_cell(centres[:, 0], centres[:, 1])
    col = np.floor(u / lat.design_pitch).astype(np.int64)
    row = np.floor(v / lat.design_pitch).astype(np.int64)
    return np.mod(row, n) * n + np.mod(col, n)


def _score(fits: AsperityFits, centres: np.ndarray, kind: np.ndarray, design: Design) -> float:
    """The share of the fitted exponents' and tip heights' variation that the common map
    (exponent shift; positive height scale and a plane) leaves unexplained, 0 to 1."""
    g_design = design.gamma[kind]
    dg = fits.gamma - g_design
    ss_g = float(((fits.gamma - fits.gamma.mean()) ** 2).sum())
    res_g = float(((dg - dg.mean()) ** 2).sum())
    frac_g = min(1.0, res_g / ss_g) if ss_g > 0 else 1.0
    h_design = (design.h - design.h.min())[kind]
    b = kind.size
    ones = np.ones(b)
    # a plane only where enough asperities pin it (else it would take up the pattern)
    plane = [centres[:, 0], centres[:, 1]] if b > 6 else []
    base = np.stack([ones, *plane], axis=1)
    full = np.stack([ones, *plane, -h_design], axis=1)
    z = fits.z0
    res0 = z - base @ np.linalg.lstsq(base, z, rcond=None)[0]
    coef, *_ = np.linalg.lstsq(full, z, rcond=None)
    res1 = z - full @ coef
    ss0 = float(res0 @ res0)
    frac_h = min(1.0, float(res1 @ res1) / ss0) if ss0 > 0 and coef[-1] > 0 else 1.0
    return 0.5 * (frac_g + frac_h)
