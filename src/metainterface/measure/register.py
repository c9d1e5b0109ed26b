"""A scan registered to its design: the lattice, the tilt, and the made asperities.

The steps (``lattice``, ``fit``): tips and the designed map give a first lattice and tilt;
every asperity is fitted on the scan so levelled; the lattice, the tilt and the asperities'
shared shapes are then fitted together, and every asperity again on that levelling. Made
heights are known only up to a common offset (a scan has no absolute zero): they are
aligned so that their mean over the asperities seen equals the design's.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from metainterface._threads import uses_threads
from metainterface.errors import MetainterfaceError
from metainterface.measure.fit import AsperityFits, fit_asperities, fit_lattice
from metainterface.measure.lattice import Lattice
from metainterface.measure.orient import Orientation, orient
from metainterface.measure.scan import Scan
from metainterface.measure.shapes import noise_floor
from metainterface.physics.cell import Design

#: Floor of the top band left out of the final asperity fits [units of Delta_max].
TOP_BAND = 0.01
#: Rounds of the lattice fit for scans that show each asperity once (``fit.fit_lattice``).
TIED_ROUNDS = 8


@dataclass(frozen=True)
class Registration:
    """Where the design lies in the scan and how its asperities came out.

    scan: the scan as registered (mirrored where the file's y axis was reversed);
    orientation: which way round the part lies (``measure.orient.Orientation``); lattice,
    tilt (2,) dz/dx, dz/dy; explained: share of the scan's height variance the designed
    map explained at the first registration. fits: every fitted asperity instance.
    Per asperity k of the design, (N,) each: gamma, h (made exponent, made height [R],
    means over the cells; the design's own where ``seen`` is 0), seen (instances fitted),
    gamma_spread, h_spread (standard deviation between cells), shift (N, 2) [R], tip_radius
    and tip_radius_design [R] (means; inf where flat).
    """

    scan: Scan
    orientation: Orientation
    lattice: Lattice
    tilt: np.ndarray
    explained: float
    fits: AsperityFits
    gamma: np.ndarray
    h: np.ndarray
    seen: np.ndarray
    gamma_spread: np.ndarray
    h_spread: np.ndarray
    shift: np.ndarray
    tip_radius: np.ndarray
    tip_radius_design: np.ndarray
    level: float = 0.0


def check_size(scan: Scan, design: Design) -> float:
    """The design's lattice pitch L / n [R]; raises if the scan is smaller than one lattice
    cell (an asperity's square) along x or y."""
    pitch = design.settings.cell_side / design.settings.n_side
    width, height = scan.size
    if min(width, height) < pitch:
        um = 1e6 * scan.radius_m
        raise MetainterfaceError(
            f"scan is smaller than one lattice cell: {width * um:.4g} x {height * um:.4g} um, "
            f"the design's cell at this radius is {pitch * um:.4g} um wide"
        )
    return pitch


@uses_threads()
def register(scan: Scan, design: Design) -> Registration:
    """Register ``scan`` (lengths in R) to ``design``; see the module docstring."""
    pitch = check_size(scan, design)
    scan, lattice, tilt, explained, orientation = orient(scan, design, pitch)
    fits = fit_asperities(scan, design, lattice, tilt)
    n = design.n_asperities
    if fits.kind.size:
        z0, gamma, _ = _by_kind(fits, n, design)
        tied = not _repeated(fits)
        # a scan of part of a cell levels slowly (tilt, shapes and heights trade off over few
        # asperities); it is small, so more rounds cost little
        refined = fit_lattice(
            scan,
            design,
            lattice,
            tilt,
            z0,
            gamma,
            tied=tied,
            rounds=TIED_ROUNDS if tied else 2,
            # a unit slip's heights are 1000 times the design's: its unknowns scaled to match
            height_scale=orientation.height_scale if orientation.unit_slip else 1.0,
        )
        lattice, tilt = refined.lattice, refined.tilt
        # the final fit leaves each top's noise band out: a flat tip's plateau is no power
        # law's, and its flank still gives where the tip would have been
        band = 3.0 * noise_floor(scan) + TOP_BAND * design.settings.delta_max
        fits = fit_asperities(scan, design, lattice, tilt, top_band=band)
    if fits.kind.size == 0:
        raise MetainterfaceError(
            "scan does not show this design's lattice: no asperity is seen whole enough to fit"
        )
    return _summarise(scan, orientation, design, lattice, tilt, explained, fits)


def _repeated(fits: AsperityFits) -> bool:
    """Whether every asperity seen is seen in two cells or more along both x and y."""
    for k in np.unique(fits.kind):
        cells = fits.cell[fits.kind == k]
        if len(np.unique(cells[:, 0])) < 2 or len(np.unique(cells[:, 1])) < 2:
            return False
    return True


def _by_kind(
    fits: AsperityFits, n: int, design: Design
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Per-asperity means of z0 and gamma over the cells (unseen: the design's, z0 from the
    design aligned to the seen ones), and the instance counts (N,)."""
    seen = np.bincount(fits.kind, minlength=n)
    z0 = np.bincount(fits.kind, fits.z0, minlength=n) / np.maximum(seen, 1)
    gamma = np.bincount(fits.kind, fits.gamma, minlength=n) / np.maximum(seen, 1)
    h_design = design.h - design.h.min()
    ok = seen > 0
    shift = np.mean(z0[ok] + h_design[ok])
    z0 = np.where(ok, z0, shift - h_design)
    gamma = np.where(ok, gamma, design.gamma)
    return z0, gamma, seen


def _summarise(
    scan: Scan,
    orientation: Orientation,
    design: Design,
    lattice: Lattice,
    tilt: np.ndarray,
    explained: float,
    fits: AsperityFits,
) -> Registration:
    n = design.n_asperities
    z0, gamma, seen = _by_kind(fits, n, design)
    h_design = design.h - design.h.min()
    ok = seen > 0
    offset = np.mean(-z0[ok] - h_design[ok])  # made heights aligned on the design's mean
    h = -z0 - offset

    def spread(values: np.ndarray) -> np.ndarray:
        out = np.zeros(n)
        for k in range(n):
            sel = fits.kind == k
            out[k] = values[sel].std() if sel.sum() > 1 else 0.0
        return out

    def mean(values: np.ndarray, fill: float) -> np.ndarray:
        out = np.full(n, fill)
        for k in range(n):
            sel = (fits.kind == k) & np.isfinite(values)
            if sel.any():
                out[k] = values[sel].mean()
        return out

    shift = np.stack([mean(fits.shift[:, 0], 0.0), mean(fits.shift[:, 1], 0.0)], axis=1)
    return Registration(
        scan=scan,
        orientation=orientation,
        lattice=lattice,
        tilt=np.asarray(tilt, dtype=np.float64),
        explained=explained,
        fits=fits,
        gamma=gamma,
        h=h,
        seen=seen,
        gamma_spread=spread(fits.gamma),
        h_spread=spread(fits.z0),
        shift=shift,
        tip_radius=mean(fits.tip_radius, np.inf),
        tip_radius_design=mean(fits.tip_radius_design, np.inf),
        level=float(offset),
    )
