"""Normal contact of a periodic cell with the boundary element method (paper sec. 4.1).

A rigid periodic surface (the cell's height map, tips up) is pressed on an elastic half-space
with E* = 1 (E = 1, nu = 0), so pressures are P* = P / E* and p / E*. The Polonsky-Keer-Rey
solver (tolerance 1e-11) is driven by the mean pressure; a load path of ascending pressures
starts each solve from the previous solution.

Two engines solve it (``engines``): our own in torch (``torch_bem``, the default) and
Tamaas's (``tamaas_path``, the ``bem`` extra). Parallelism over a load path is by processes
(``solve_loads`` with ``jobs > 1`` splits it into contiguous chunks, each solved on one
torch thread); one process may also run torch on several threads.
"""

from __future__ import annotations

import contextlib
import multiprocessing as mp
import os
import sys
import time
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass
from types import ModuleType
from typing import Any

import numpy as np

from metainterface._process import die_with_parent
from metainterface.errors import MetainterfaceError

#: Convergence tolerance of the Polonsky-Keer-Rey solver (the paper's value).
TOLERANCE = 1e-11
#: Iteration cap per solve (Tamaas's default). 768^2 cells converge in ~110 iterations.
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


def solve_path(
    heights: np.ndarray,
    cell_side: float,
    loads: np.ndarray,
    owner: np.ndarray,
    n_asperities: int,
    *,
    engine: Any = None,
    device: Any = "auto",
    threads: int | None = None,
    tolerance: float = TOLERANCE,
    max_iter: int = MAX_ITER,
    first_index: int = 0,
    total: int | None = None,
    report: Callable[[int], Any] | None = None,
    fields: bool = False,
) -> LoadPath:
    """Solve the contact of one cell at ascending mean pressures ``loads`` (K,) [P* = P/E*].

    heights: (M, M) surface [length], tips up; cell_side: L [same length]; owner: (M, M)
    asperity index of each grid point. engine: "torch" (default) or "tamaas"
    (``engines.ENGINES``); device: where torch solves ("auto", "cpu", "cuda", "cuda:N");
    threads: torch threads for the solve (None: as set). The first load starts from a
    uniform pressure, each next one from the previous solution. ``report(1)`` is called
    after each load. ``first_index`` and ``total`` only number the loads in error messages
    (for chunks of a longer path). fields: also keep the pressure and gap fields of every
    load (``LoadPath.pressures``, ``gaps``; 2 K M^2 floats). Raises MetainterfaceError
    naming the load and the residual if a solve does not converge.
    """
    from metainterface.validation.engines import get_engine

    return get_engine(engine).solve_path(
        heights,
        cell_side,
        loads,
        owner,
        n_asperities,
        tolerance=tolerance,
        max_iter=max_iter,
        first_index=first_index,
        total=total,
        report=report,
        fields=fields,
        device=device,
        threads=threads,
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
    k = len(loads)
    alpha, alpha_pixels, p_max, residual, seconds = (np.empty(k) for _ in range(5))
    per = np.empty((k, n_asperities))
    owner_flat = np.asarray(owner).ravel()
    pressures = np.empty((k, m, m)) if fields else None
    gaps = np.empty((k, m, m)) if fields else None
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
            seconds[i] = time.perf_counter() - start
            if not err <= tolerance:
                raise MetainterfaceError(
                    f"BEM did not converge at load {first_index + i + 1} of {total} "
                    f"(P* = {p:.6g}): residual {err:.3g} > tolerance {tolerance:g} "
                    f"after {max_iter} iterations"
                )
            traction = model.traction.reshape(m, m)
            alpha[i], per[i], alpha_pixels[i] = contact_area(traction, owner_flat, n_asperities)
            p_max[i] = float(traction.max())
            residual[i] = err
            if pressures is not None and gaps is not None:
                pressures[i] = traction
                # Tamaas's displacement equals the surface where in contact: gap = u - z >= 0
                gaps[i] = model.displacement.reshape(m, m) - surface
            if report is not None:
                report(1)
        pressure = np.array(model.traction.reshape(m, m), copy=True)
    return LoadPath(alpha, alpha_pixels, p_max, per, residual, seconds, pressure, pressures, gaps)


# --- processes ---------------------------------------------------------------------------

_progress_queue: Any = None


def _init_worker(queue: Any, parent: int | None = None) -> None:
    global _progress_queue
    die_with_parent(parent)  # a killed parent takes its workers with it
    _progress_queue = queue


def _report_to_queue(n: int) -> None:
    if _progress_queue is not None:
        _progress_queue.put(n)


def _solve_task(kwargs: dict[str, Any]) -> LoadPath:
    # a forked worker runs torch on one thread (several hang after a multi-threaded parent)
    return solve_path(**{"threads": 1, **kwargs}, report=_report_to_queue)


def _context() -> mp.context.BaseContext:
    # fork: workers start in milliseconds and need no imports (torch runs there on one
    # thread). Where fork is unavailable or unsafe (macOS, Windows), spawn.
    if sys.platform.startswith("linux"):
        return mp.get_context("fork")
    return mp.get_context("spawn")  # pragma: no cover


def available_cpus() -> int:
    """Cores this process may use."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # pragma: no cover - not Linux
        return os.cpu_count() or 1


def run_tasks(
    tasks: Sequence[dict[str, Any] | Callable[[], dict[str, Any]]],
    jobs: int,
    *,
    progress: Callable[[int], Any] | None = None,
    on_done: Callable[[int, LoadPath], Any] | None = None,
    on_error: Callable[[int, BaseException], Any] | None = None,
) -> list[LoadPath | None]:
    """Run ``solve_path(**task)`` for each task on up to ``jobs`` processes.

    A task is a dict of keyword arguments, or a function returning one, called only when a
    process is free (so a long sweep holds one height map per process, not one per design).
    progress(n) is called in this process as loads finish; on_done(i, result) as each task
    finishes (results are also returned, in order, unless on_done is given). A failing task
    raises at once (other workers are stopped) unless ``on_error`` is given, which then
    receives it and the task's slot stays None.
    """
    results: list[LoadPath | None] = [None] * len(tasks)

    def kwargs(i: int) -> dict[str, Any]:
        task = tasks[i]
        return task() if callable(task) else task

    def finish(i: int, get: Callable[[], LoadPath]) -> None:
        try:
            path = get()
        except MetainterfaceError as exc:
            if on_error is None:
                raise
            on_error(i, exc)
            return
        if on_done is None:
            results[i] = path
        else:
            on_done(i, path)

    if jobs <= 1 or len(tasks) <= 1:
        for i in range(len(tasks)):
            finish(i, lambda i=i: solve_path(**kwargs(i), report=progress))
        return results
    ctx = _context()
    queue = ctx.Queue()
    workers = min(jobs, len(tasks))
    pool = ctx.Pool(workers, initializer=_init_worker, initargs=(queue, os.getpid()))
    try:
        waiting = iter(range(len(tasks)))
        running: dict[int, Any] = {}
        while True:
            while len(running) < workers:  # keep every process busy, no more
                i = next(waiting, None)
                if i is None:
                    break
                running[i] = pool.apply_async(_solve_task, (kwargs(i),))
            if not running:
                break
            for i, res in list(running.items()):
                if res.ready():
                    del running[i]
                    finish(i, res.get)
            _drain(queue, progress, block=bool(running))
        pool.close()
        pool.join()
    finally:
        pool.terminate()
        _drain(queue, progress, block=False)
    return results


def _drain(queue: Any, progress: Callable[[int], Any] | None, *, block: bool) -> None:
    import queue as queue_mod

    try:
        n = queue.get(timeout=0.2) if block else queue.get_nowait()
        while True:
            if progress is not None:
                progress(n)
            n = queue.get_nowait()
    except queue_mod.Empty:
        pass


def split_path(k: int, jobs: int, weights: np.ndarray | None = None) -> list[np.ndarray]:
    """Split load indices 0..k-1 into at most ``jobs`` contiguous, non-empty chunks of about
    equal total weight (equal sizes without weights)."""
    jobs = max(1, min(jobs, k))
    w = np.ones(k) if weights is None else np.asarray(weights, dtype=np.float64)
    cum = np.concatenate([[0.0], np.cumsum(w) / w.sum()])  # weight before load i
    # chunk j ends where the cumulative weight is nearest to (j + 1) / jobs
    targets = np.arange(1, jobs) / jobs + 1e-9  # ties: the earlier (lighter) chunk grows
    ends = np.abs(cum[None, :] - targets[:, None]).argmin(axis=1)
    ends = np.maximum(ends, np.arange(1, jobs))  # at least one load per chunk ...
    ends = np.minimum(ends, k - jobs + np.arange(1, jobs))  # ... leaving one for the rest
    ends = np.maximum.accumulate(ends)
    return [c for c in np.split(np.arange(k), ends) if c.size]


def solve_loads(
    heights: np.ndarray,
    cell_side: float,
    loads: np.ndarray,
    owner: np.ndarray,
    n_asperities: int,
    *,
    jobs: int = 1,
    engine: Any = None,
    device: Any = "auto",
    tolerance: float = TOLERANCE,
    max_iter: int = MAX_ITER,
    weights: np.ndarray | None = None,
    progress: Callable[[int], Any] | None = None,
    fields: bool = False,
) -> LoadPath:
    """One cell's load path (K,), split into ``jobs`` contiguous warm-started chunks.

    Each chunk starts from zero traction and then follows its own part of the path; the
    solution is unique, so chunking changes results only within the tolerance. weights: (K,)
    expected relative cost of each load, to balance the chunks (default: equal).
    """
    loads = np.asarray(loads, dtype=np.float64)
    chunks = split_path(len(loads), jobs, weights)
    common = dict(
        heights=heights,
        cell_side=cell_side,
        owner=owner,
        n_asperities=n_asperities,
        engine=engine,
        device=device,
        tolerance=tolerance,
        max_iter=max_iter,
        total=len(loads),
        fields=fields,
    )
    tasks = [{**common, "loads": loads[c], "first_index": int(c[0])} for c in chunks]
    parts = run_tasks(tasks, jobs, progress=progress)
    return LoadPath.concat([p for p in parts if p is not None])
