"""One load path of a cell in BEM: what it holds (:class:`LoadPath`), how it is recorded
(:class:`PathRecorder`), the solver's settings, and Tamaas's engine (``tamaas_path``, the
``bem`` extra). ``bem`` drives the paths (engines, processes, chunks)."""

from __future__ import annotations

import contextlib
import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from types import ModuleType
from typing import Any

import numpy as np

from metainterface.errors import MetainterfaceError

#: Convergence tolerance of the Polonsky-Keer-Rey solver (the paper's value).
TOLERANCE = 1e-11
#: Iteration cap per solve (Tamaas's default; the torch engine takes a few tens at 768^2).
MAX_ITER = 1000

INSTALL_HINT = "pip install 'metainterface[bem]'"


def require_tamaas() -> ModuleType:
    """Import Tamaas, or raise a one-line MetainterfaceError with the install command."""
    try:
        import tamaas
    except ImportError:
        raise MetainterfaceError(
            f"BEM validation needs Tamaas, which is not installed: run `{INSTALL_HINT}`"
        ) from None
    return tamaas


@dataclass(frozen=True)
class LoadPath:
    """BEM measurements along a load path of K mean pressures.

    alpha: (K,) contact area fraction, edges placed to sub-pixel accuracy (``contact_area``).
    alpha_pixels: (K,) fraction of grid points in contact (the plain count). p_max: (K,)
    largest local p / E*. asperity_alpha: (K, N) contact area of each asperity / A_nom (its
    lattice cell's share of ``alpha``). residual: (K,) the solver's final error.
    seconds: (K,) wall time of each solve. pressure: (M, M) p / E* at the last load.
    pressures, gaps: (K, M, M) p / E* and the gap [length] at every load, kept only when
    the path was solved with ``fields=True`` (else None).
    """

    alpha: np.ndarray
    alpha_pixels: np.ndarray
    p_max: np.ndarray
    asperity_alpha: np.ndarray
    residual: np.ndarray
    seconds: np.ndarray
    pressure: np.ndarray
    pressures: np.ndarray | None = None
    gaps: np.ndarray | None = None

    @staticmethod
    def concat(parts: list[LoadPath]) -> LoadPath:
        """Join chunks of one path, in order; the pressure field is the last chunk's."""
        return LoadPath(
            alpha=np.concatenate([p.alpha for p in parts]),
            alpha_pixels=np.concatenate([p.alpha_pixels for p in parts]),
            p_max=np.concatenate([p.p_max for p in parts]),
            asperity_alpha=np.concatenate([p.asperity_alpha for p in parts]),
            residual=np.concatenate([p.residual for p in parts]),
            seconds=np.concatenate([p.seconds for p in parts]),
            pressure=parts[-1].pressure,
            pressures=_stack([p.pressures for p in parts]),
            gaps=_stack([p.gaps for p in parts]),
        )


def _stack(parts: list[np.ndarray | None]) -> np.ndarray | None:
    if any(p is None for p in parts):
        return None
    return np.concatenate(parts)  # type: ignore[arg-type]


@contextlib.contextmanager
def _quiet(tm: ModuleType) -> Iterator[None]:
    """Silence Tamaas's per-solve iteration log (printed at its default 'info' level)."""
    level = tm.get_log_level()
    tm.set_log_level(tm.LogLevel.error)
    try:
        yield
    finally:
        tm.set_log_level(level)


def contact_area(
    pressure: np.ndarray, owner: np.ndarray, n_asperities: int
) -> tuple[float, np.ndarray, float]:
    """Contact area of a periodic M x M pressure field, with edges to sub-pixel accuracy.

    pressure: (M, M) p / E* (in contact where > 0); owner: (M * M,) or (M, M) asperity
    index of each grid point. Returns (alpha, per-asperity alpha (N,), pixel alpha), all as
    fractions of the cell.

    Counting grid points in contact puts every contact edge half-way between the last point
    in contact and the first one out, which reads alpha high (an edge's offset of ~0.5 grid
    step on the contact radius; worse and noisy for the first contacts). Near the edge of a
    smooth contact the pressure falls as the square root of the distance to the edge, so p^2
    is linear in it: along each grid line, p^2 at an edge point and at its neighbour inside
    extrapolate to zero at the edge, a fraction t = p_e^2 / (p_in^2 - p_e^2) of a step
    beyond the edge point (clipped to [0, 1]; 0.5, the count's value, where a run is one
    point long or p does not rise inwards). The area is the count plus sum (t - 1/2) over
    the edge points of the rows, averaged with the same along the columns. Its accuracy
    against Sneddon's closed forms is measured by benchmarks/bench_contact_area.py (bounds
    in tests/validation/test_bem.py). It still reads small contacts high: on grid lines that
    graze an edge, p^2 is not linear over a step."""
    p = np.asarray(pressure, dtype=np.float64)
    owner = np.asarray(owner).ravel()
    m = p.shape[0]
    inside = p > 0
    q = np.where(inside, p, 0.0) ** 2
    count = np.bincount(owner[inside.ravel()], minlength=n_asperities).astype(np.float64)
    shift = np.zeros(n_asperities)
    for axis in (0, 1):
        for step in (1, -1):
            # edge points: in contact, the next point along +step is not
            edge = inside & ~np.roll(inside, -step, axis=axis)
            q_in = np.roll(q, step, axis=axis)  # the neighbour on the inner side
            rising = edge & (q_in > q)
            t = np.full(p.shape, 0.5)
            t[rising] = np.clip(q[rising] / (q_in[rising] - q[rising]), 0.0, 1.0)
            shift += np.bincount(
                owner, weights=np.where(edge, t - 0.5, 0.0).ravel(), minlength=n_asperities
            )
    per = (count + 0.5 * shift) / (m * m)  # the mean of the row and the column estimates
    return float(per.sum()), per, float(count.sum()) / (m * m)


class PathRecorder:
    """Collects the solved loads of a path (K loads on an M x M grid) into a ``LoadPath``."""

    def __init__(self, k: int, m: int, owner: np.ndarray, n_asperities: int, fields: bool):
        self.alpha, self.alpha_pixels, self.p_max, self.residual, self.seconds = (
            np.empty(k) for _ in range(5)
        )
        self.per = np.empty((k, n_asperities))
        self.owner = np.asarray(owner).ravel()
        self.n_asperities = n_asperities
        self.pressures = np.empty((k, m, m)) if fields else None
        self.gaps = np.empty((k, m, m)) if fields else None
        self.pressure: np.ndarray | None = None

    def record(
        self, i: int, pressure: np.ndarray, gap: np.ndarray | None, err: float, seconds: float
    ) -> None:
        """Load i: its (M, M) pressure p / E* and gap [length], solver error and time."""
        self.alpha[i], self.per[i], self.alpha_pixels[i] = contact_area(
            pressure, self.owner, self.n_asperities
        )
        self.p_max[i] = float(pressure.max())
        self.residual[i] = err
        self.seconds[i] = seconds
        if self.pressures is not None and self.gaps is not None and gap is not None:
            self.pressures[i] = pressure
            self.gaps[i] = gap
        self.pressure = np.array(pressure, copy=True)

    def path(self) -> LoadPath:
        assert self.pressure is not None
        return LoadPath(
            self.alpha,
            self.alpha_pixels,
            self.p_max,
            self.per,
            self.residual,
            self.seconds,
            self.pressure,
            self.pressures,
            self.gaps,
        )


def tamaas_path(
    heights: np.ndarray,
    cell_side: float,
    loads: np.ndarray,
    owner: np.ndarray,
    n_asperities: int,
    *,
    tolerance: float = TOLERANCE,
    max_iter: int = MAX_ITER,
    first_index: int = 0,
    total: int | None = None,
    report: Callable[[int], Any] | None = None,
    fields: bool = False,
) -> LoadPath:
    """``solve_path`` with Tamaas's PolonskyKeerRey (one thread; Tamaas keeps the traction
    field between solves, which warm-starts each load from the previous one)."""
    tm = require_tamaas()
    loads = np.asarray(loads, dtype=np.float64)
    total = len(loads) if total is None else total
    surface = np.ascontiguousarray(heights, dtype=np.float64)  # Tamaas keeps a reference
    m = surface.shape[0]
    rec = PathRecorder(len(loads), m, owner, n_asperities, fields)
    with _quiet(tm):
        model = tm.ModelFactory.createModel(tm.model_type.basic_2d, [float(cell_side)] * 2, [m, m])
        model.E, model.nu = 1.0, 0.0  # E* = E / (1 - nu^2) = 1
        if abs(model.E_star - 1.0) > 1e-14:  # pragma: no cover - a Tamaas API change
            raise MetainterfaceError(f"Tamaas model has E* = {model.E_star}, expected 1")
        solver = tm.PolonskyKeerRey(model, surface, tolerance)
        solver.max_iter = int(max_iter)
        for i, p in enumerate(loads):
            start = time.perf_counter()
            try:
                err = float(solver.solve(float(p)))
            except (RuntimeError, ArithmeticError) as exc:  # Tamaas's own checks
                raise MetainterfaceError(
                    f"BEM failed at load {first_index + i + 1} of {total} (P* = {p:.6g}): "
                    f"{str(exc).strip().splitlines()[-1]} (try a finer grid)"
                ) from None
            sec = time.perf_counter() - start
            if not err <= tolerance:
                raise MetainterfaceError(
                    f"BEM did not converge at load {first_index + i + 1} of {total} "
                    f"(P* = {p:.6g}): residual {err:.3g} > tolerance {tolerance:g} "
                    f"after {max_iter} iterations"
                )
            # Tamaas's displacement equals the surface where in contact: gap = u - z >= 0
            gap = model.displacement.reshape(m, m) - surface if fields else None
            rec.record(i, model.traction.reshape(m, m), gap, err, sec)
            if report is not None:
                report(1)
        rec.pressure = np.array(model.traction.reshape(m, m), copy=True)  # also for no loads
    return rec.path()
