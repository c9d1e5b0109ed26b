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

import multiprocessing as mp
import os
import sys
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np

from metainterface._process import die_with_parent
from metainterface.errors import MetainterfaceError
from metainterface.validation.loadpath import (
    INSTALL_HINT,
    MAX_ITER,
    TOLERANCE,
    LoadPath,
    PathRecorder,
    contact_area,
    require_tamaas,
    tamaas_path,
)

__all__ = [
    "INSTALL_HINT",
    "MAX_ITER",
    "TOLERANCE",
    "LoadPath",
    "PathRecorder",
    "available_cpus",
    "contact_area",
    "require_tamaas",
    "run_tasks",
    "solve_loads",
    "solve_path",
    "split_path",
    "tamaas_path",
]


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
    contact_depth: np.ndarray | None = None,
) -> LoadPath:
    """Solve the contact of one cell at ascending mean pressures ``loads`` (K,) [P* = P/E*].

    heights: (M, M) surface [length], tips up; cell_side: L [same length]; owner: (M, M)
    asperity index of each grid point. engine: "torch" (default) or "tamaas"
    (``engines.ENGINES``); device: where torch solves ("auto", "cpu", "cuda", "cuda:N");
    threads: torch threads for the solve (None: as set). The first load starts from a
    uniform pressure, each next one from the previous solution. ``report(1)`` is called
    after each load. ``first_index`` and ``total`` only number the loads in error messages
    (for chunks of a longer path). fields: also keep the pressure and gap fields of every
    load (``LoadPath.pressures``, ``gaps``; 2 K M^2 floats). contact_depth: (N,) where a
    forward model puts each asperity's contact edge at the first load, as its depth below
    the tip, c a^gamma [length]: the torch engine starts there (``torch_bem.contact_start``)
    instead of from a uniform pressure. Raises MetainterfaceError naming the load and the
    residual if a solve does not converge.
    """
    from metainterface.validation.solvers import get_engine

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
        contact_depth=contact_depth,
    )


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
    contact_depths: np.ndarray | None = None,
) -> LoadPath:
    """One cell's load path (K,), split into ``jobs`` contiguous warm-started chunks.

    Each chunk starts afresh (from ``contact_depths[first load]`` (K, N) if given, see
    ``solve_path``) and then follows its own part of the path; the solution is unique, so
    chunking changes results only within the tolerance. weights: (K,) expected relative
    cost of each load, to balance the chunks (default: equal).
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
    tasks = [
        {
            **common,
            "loads": loads[c],
            "first_index": int(c[0]),
            "contact_depth": None if contact_depths is None else contact_depths[c[0]],
        }
        for c in chunks
    ]
    parts = run_tasks(tasks, jobs, progress=progress)
    return LoadPath.concat([p for p in parts if p is not None])
