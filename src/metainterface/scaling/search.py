"""The scale of a friction law as a design variable: which area, modulus or shear strength
makes the law reachable by the cell.

A law in newtons becomes the target alpha = F_f / (tau A), P* = F_n / (A E*) (Bowden and
Tabor, paper sec. 2.3). Scaling the nominal area A by k moves every point along its ray
through the origin (P*, alpha) -> (P*, alpha) / k; scaling E* by k moves P* alone, tau by k
alpha alone. The radius R does not move the target (P* and alpha are averages over the
nominal area); it sets the cell side L R and so how many cells tile the area. The cell
reaches, at each P*, an envelope of alpha (:func:`~metainterface.inverse.pipeline.
reachable_envelope`); a scale is feasible when every point of the law lies inside it (within
``tolerance``) and below the largest P* any design reaches. The envelope is pointwise, so a
feasible scale is necessary for a close design, not a proof of one: the design decides.

With a work of adhesion w [J/m^2] the cells are JKR cells of adhesion w / (E* R) (issue 38),
and the envelope is theirs: area and tau leave w / (E* R) as it is, the modulus moves it, so
each modulus searched has an envelope of its own (computed once each, cached). The modulus
is then searched on a coarser grid (``ADHESIVE_PER_DECADE``) within ``ADHESIVE_DECADES``
of the given value, and no softer than w / (E* R) <= ``ADHESION_LIMIT`` allows.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from metainterface.errors import MetainterfaceError
from metainterface.inverse.envelope import TOLERANCE, reach_violation
from metainterface.physics.cell import CellSettings
from metainterface.physics.jkr import ADHESION_LIMIT

#: The scale variables: how a factor k on each moves the target (P*, alpha).
VARIABLES = ("area", "modulus", "shear_strength")
#: Decades searched either side of the given value, and grid points per decade (a 1 %
#: step: finer than any unit the ranges are reported in).
DECADES = 3.0
PER_DECADE = 230
#: With adhesion, the modulus's search: decades either side and grid points per decade
#: (each point an adhesive envelope of its own, ~0.5-1 s on two CPU cores).
ADHESIVE_DECADES = 1.0
ADHESIVE_PER_DECADE = 10


def _moved(p: np.ndarray, a: np.ndarray, variable: str, k: np.ndarray) -> tuple[Any, Any]:
    """(S, K) targets for factors k (S,) on ``variable``, from the law's (K,) target."""
    kk = k[:, None]
    if variable == "area":
        return p[None] / kk, a[None] / kk
    if variable == "modulus":
        return p[None] / kk, np.broadcast_to(a[None], (k.size, a.size))
    return np.broadcast_to(p[None], (k.size, p.size)), a[None] / kk


def violation(
    p_star: np.ndarray,
    alpha: np.ndarray,
    settings: CellSettings,
    tolerance: float = TOLERANCE,
    adhesion: float | np.ndarray = 0.0,
) -> tuple[np.ndarray, np.ndarray]:
    """How far targets (S, K) leave the reachable envelope: (mean violation (S,), points
    outside (S,)), from the one reach test (:func:`~metainterface.inverse.envelope.
    reach_violation`) that ``reachability`` and ``design`` ask too. adhesion: w / (E* R),
    one number or one per target (S,)."""
    v = reach_violation(p_star, alpha, settings, tolerance, adhesion=adhesion)
    return v.mean(-1), (v > 0).sum(-1)


@dataclass(frozen=True)
class FeasibleScale:
    """Which scales make a friction law reachable by the cell.

    given: the scale asked for, SI ({'area': m^2, 'modulus': Pa, 'shear_strength': Pa,
    'radius': m}). outside: points of the law outside the envelope at the given scale (of
    ``points``). ranges: per variable, the intervals [SI] that make it reachable with the
    other two as given (empty: none within 10^3 of the given value and the bounds). best:
    per variable, the value with the smallest violation (the middle of the widest range
    where there is one), and ``best_outside`` the points still outside there. bounds: per
    variable, the (low, high) the search was limited to [SI].
    """

    given: dict[str, float]
    outside: int
    points: int
    ranges: dict[str, list[tuple[float, float]]]
    best: dict[str, float]
    best_outside: dict[str, int]
    bounds: dict[str, tuple[float, float]] = field(default_factory=dict)
    cell_area: float = 0.0
    #: The work of adhesion w [J/m^2] the cells were tested with (0: none).
    work_of_adhesion: float = 0.0

    @property
    def reachable(self) -> bool:
        """Whether the law is reachable at the given scale."""
        return self.outside == 0

    def suggest(self) -> dict[str, float]:
        """A scale to design the law at, SI ({'area', 'modulus', 'shear_strength',
        'radius'}): the given one with the first of area, modulus, shear strength that has a
        feasible range set to its best value there; where none has, the one that leaves the
        fewest points outside set to its closest value."""
        var = next((v for v in VARIABLES if self.ranges.get(v)), None)
        if var is None:
            var = min(self.best, key=lambda v: self.best_outside[v])
        return {**self.given, var: self.best[var]}

    def tiles(self, area: float) -> tuple[float, int]:
        """(cells, cells per side) that tile a nominal area [m^2]."""
        n = area / self.cell_area
        return n, math.ceil(math.sqrt(n) - 1e-9)

    def summary(self) -> list[str]:
        """One or two lines in the user's units: reachable or not, and what to change."""
        g = self.given
        at = f"E* = {fmt_pressure(g['modulus'])}, tau = {fmt_pressure(g['shear_strength'])}"
        if self.work_of_adhesion:
            at += f", w = {self.work_of_adhesion * 1e3:.3g} mJ/m^2"
        head = (
            f"reachable at the given scale (area {fmt_area(g['area'])}, {at})"
            if self.reachable
            else f"not reachable at area {fmt_area(g['area'])}, {at}: {self.outside} of "
            f"{self.points} points outside what the cell reaches"
        )
        options = []
        for var in VARIABLES:
            spans = self.ranges.get(var, [])
            if not spans:
                continue
            text = " or ".join(_span(var, lo, hi) for lo, hi in spans)
            options.append(f"{_NAMES[var]} of {text}")
        if options:
            tail = "reachable with " + "; or with ".join(options) + " (the others as given)"
        else:
            var = min(self.best, key=lambda v: self.best_outside[v])
            tail = (
                f"no area, E* or tau within the searched range (10^{DECADES:g} of the given"
                + (f"; E* 10^{ADHESIVE_DECADES:g} with adhesion" if self.work_of_adhesion else "")
                + ") makes it reachable; "
                f"closest: {_NAMES[var]} {_fmt(var, self.best[var])} "
                f"({self.best_outside[var]} points outside)"
            )
        return [head, tail]

    def record(self) -> dict[str, Any]:
        """JSON-ready, SI."""
        return {
            "given": self.given,
            "outside": self.outside,
            "points": self.points,
            "ranges": {k: [list(s) for s in v] for k, v in self.ranges.items()},
            "best": self.best,
            "best_outside": self.best_outside,
            "work_of_adhesion_j_m2": self.work_of_adhesion,
            "summary": self.summary(),
        }


_NAMES = {"area": "an area", "modulus": "E*", "shear_strength": "tau"}


def fmt_area(a: float) -> str:
    """An area [m^2] in mm^2, cm^2 or m^2, three significant digits."""
    for unit, f, at in (("m^2", 1.0, 0.1), ("cm^2", 1e-4, 1e-4), ("mm^2", 1e-6, 0.0)):
        if a >= at:
            return f"{a / f:.3g} {unit}"
    raise AssertionError  # pragma: no cover


def fmt_pressure(p: float) -> str:
    """A pressure [Pa] in Pa, kPa, MPa or GPa, three significant digits."""
    for unit, f in (("GPa", 1e9), ("MPa", 1e6), ("kPa", 1e3), ("Pa", 1.0)):
        if p >= f or unit == "Pa":
            return f"{p / f:.3g} {unit}"
    raise AssertionError  # pragma: no cover


def _fmt(var: str, v: float) -> str:
    return fmt_area(v) if var == "area" else fmt_pressure(v)


def _span(var: str, lo: float, hi: float) -> str:
    """'6.1-9.8 cm^2' (one unit) or '800 kPa-1.2 MPa'; 'about 18 MPa' where the two read
    alike (a range one grid point wide: '18-18 MPa' said nothing)."""
    a, b = _fmt(var, lo), _fmt(var, hi)
    if a == b:
        return f"about {a}"
    ua, ub = a.split(" ", 1)[1], b.split(" ", 1)[1]
    return f"{a.split(' ', 1)[0]}-{b}" if ua == ub else f"{a}-{b}"


def _runs(ok: np.ndarray) -> list[tuple[int, int]]:
    """Index ranges [i, j] of the True runs in a boolean row."""
    edges = np.flatnonzero(np.diff(np.concatenate([[0], ok.astype(int), [0]])))
    return [(int(a), int(b) - 1) for a, b in zip(edges[::2], edges[1::2], strict=True)]


#: Feasible ranges closer than this ratio are reported as one: the envelope is an estimate
#: from a finite family of cells, and a gap of a grid step or two is its noise.
MERGE_RATIO = 1.15


def _merged(runs: list[tuple[int, int]], values: np.ndarray) -> list[tuple[int, int]]:
    out: list[tuple[int, int]] = []
    for i, j in runs:
        if out and values[i] / values[out[-1][1]] < MERGE_RATIO:
            out[-1] = (out[-1][0], j)
        else:
            out.append((i, j))
    return out


def scan_grid(bounds: tuple[float, float], adhesive_modulus: bool = False) -> np.ndarray:
    """The values [SI] a variable is tested at within ``bounds``: a log grid of
    ``PER_DECADE`` points a decade (``ADHESIVE_PER_DECADE`` for the modulus with adhesion,
    each point of which has an envelope of its own)."""
    lo, hi = bounds
    per_decade = ADHESIVE_PER_DECADE if adhesive_modulus else PER_DECADE
    steps = max(2, round(math.log10(hi / lo) * per_decade) + 1)
    return np.geomspace(lo, hi, steps)


def scan(
    p_star: np.ndarray,
    alpha: np.ndarray,
    variable: str,
    given: float,
    bounds: tuple[float, float],
    settings: CellSettings,
    adhesion: float = 0.0,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(values (S,) SI, mean violation (S,), points outside (S,)) over a log grid of the
    variable within ``bounds``, from the target at the ``given`` value. adhesion: w / (E* R)
    at the given value (the modulus moves it: w / (E* R) scales as 1 / E*)."""
    moves_w = bool(adhesion) and variable == "modulus"
    values = scan_grid(bounds, moves_w)
    p, a = _moved(p_star, alpha, variable, values / given)
    w = adhesion * given / values if moves_w else adhesion
    v, out = violation(np.asarray(p), np.asarray(a), settings, adhesion=w)
    return values, v, out


def feasible_scale(
    normal_force: np.ndarray,
    friction_force: np.ndarray,
    *,
    area: float,
    modulus: float,
    shear_strength: float,
    radius: float,
    settings: CellSettings | None = None,
    bounds: dict[str, tuple[float, float]] | None = None,
    work_of_adhesion: float = 0.0,
    variables: tuple[str, ...] = VARIABLES,
) -> FeasibleScale:
    """Which area, modulus or shear strength makes the law (F_n, F_f) (K,) [N] reachable.

    area [m^2], modulus E* [Pa], shear_strength tau [Pa], radius R [m]: the scale given.
    bounds: per variable, (low, high) [SI] to search in (default 10^-3 to 10^3 times the
    given value, the modulus 10^-1 to 10^1 with adhesion; the area at least one cell (L R)^2
    and large enough that alpha < 1; the modulus at least w / (R ADHESION_LIMIT)).
    work_of_adhesion: w [J/m^2] >= 0, for cells of JKR asperities. variables: the ones
    searched (the others have no ranges; ``design_scale`` searches only its free one).
    """
    s = settings or CellSettings()
    work = float(work_of_adhesion)
    if not (math.isfinite(work) and work >= 0):
        raise MetainterfaceError(f"work of adhesion must be >= 0 J/m^2, got {work_of_adhesion!r}")
    if work > ADHESION_LIMIT * modulus * radius:
        raise MetainterfaceError(
            f"work of adhesion must be in [0, {ADHESION_LIMIT * modulus * radius:g}] J/m^2 "
            f"(up to {ADHESION_LIMIT:g} E* R) at the given modulus, got {work:g}",
            argument="work_of_adhesion",
        )
    w0 = work / (modulus * radius)  # w / (E* R) at the given modulus
    given = {"area": area, "modulus": modulus, "shear_strength": shear_strength}
    fn = np.asarray(normal_force, dtype=np.float64)
    ff = np.asarray(friction_force, dtype=np.float64)
    p0, a0 = fn / (area * modulus), ff / (shear_strength * area)
    cell_area = (s.cell_side / s.radius * radius) ** 2
    _, out0 = violation(p0[None], a0[None], s, adhesion=w0)
    lim = {v: (given[v] * 10**-DECADES, given[v] * 10**DECADES) for v in VARIABLES}
    if work:
        lim["modulus"] = (modulus * 10**-ADHESIVE_DECADES, modulus * 10**ADHESIVE_DECADES)
    # alpha < 1 needs A > F_f / tau and tau > F_f / A; the area holds at least one cell;
    # w / (E* R) within the adhesive model's range
    floor = {
        "area": max(cell_area, float(ff.max()) / shear_strength * 1.0001),
        "shear_strength": float(ff.max()) / area * 1.0001,
        "modulus": work / (radius * ADHESION_LIMIT),
    }
    lim = {v: (max(lo, floor[v]), hi) for v, (lo, hi) in lim.items()}
    for var, (lo, hi) in (bounds or {}).items():
        if var not in VARIABLES:
            raise MetainterfaceError(f"bounds: unknown variable {var!r} ({', '.join(VARIABLES)})")
        lim[var] = (max(lo, floor[var]), hi)
    ranges: dict[str, list[tuple[float, float]]] = {}
    best: dict[str, float] = {}
    best_out: dict[str, int] = {}
    for var in variables:
        lo, hi = lim[var]
        if not lo < hi:
            ranges[var], best[var], best_out[var] = [], lo, int(p0.size)
            continue
        values, v, out = scan(p0, a0, var, given[var], (lo, hi), s, adhesion=w0)
        runs = _merged(_runs(out == 0), values)
        ranges[var] = [(float(values[i]), float(values[j])) for i, j in runs]
        if runs:  # the middle (in log) of the widest range: the most room either side
            i, j = max(runs, key=lambda r: r[1] - r[0])
            best[var] = float(math.sqrt(values[i] * values[j]))
            best_out[var] = 0
        else:
            k = int(np.lexsort((v, out))[0])
            best[var], best_out[var] = float(values[k]), int(out[k])
    return FeasibleScale(
        given={**given, "radius": radius},
        outside=int(out0[0]),
        points=int(p0.size),
        ranges=ranges,
        best=best,
        best_outside=best_out,
        bounds=lim,
        cell_area=cell_area,
        work_of_adhesion=work,
    )
