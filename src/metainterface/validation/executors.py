"""BEM work on any ``concurrent.futures.Executor``: local processes, a Dask cluster, MPI.

A task (``BemTask``) is one design's load path, or one warm-started chunk of it, described
by the design itself (a few hundred bytes): the worker builds the height map and solves, so
nothing large crosses the wire on the way in. ``stream`` submits tasks and hands each result
to a callback in the calling process as it arrives, so results reach the disk as they finish
whatever the engine.

Engines differ in what a dead worker does to a task. Dask reschedules it on another worker
by itself; a local process pool breaks as a whole (``BrokenProcessPool``). ``stream``
resubmits a task the engine lost (any error that is not the task's own MetainterfaceError)
up to ``retries`` times, and replaces a broken local pool that it owns.
"""

from __future__ import annotations

import concurrent.futures as cf
import multiprocessing as mp
import os
import sys
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from metainterface._process import die_with_parent
from metainterface.errors import MetainterfaceError
from metainterface.physics.cell import Design
from metainterface.validation.bem import LoadPath, solve_path
from metainterface.validation.heightmap import height_map
from metainterface.validation.solvers import torch_threads

#: Times a task the engine lost (a dead worker, a broken pool) is submitted again.
RETRIES = 2


@dataclass(frozen=True)
class BemTask:
    """One BEM solve: ``loads`` (k,) ascending P*, loads first_index .. first_index + k - 1
    of a path of ``total``, of ``design`` on a grid x grid map, by ``engine`` on ``device``
    (resolved in the worker) with torch on ``threads`` threads (None: as set there)."""

    design: Design
    grid: int
    loads: np.ndarray
    first_index: int
    total: int
    tolerance: float
    max_iter: int
    fields: bool = False
    engine: str = "torch"
    device: str = "auto"
    threads: int | None = 1
    #: (N,) the forward model's contact edges at the first load (``bem.solve_path``)
    contact_depth: np.ndarray | None = None


def solve_task(task: BemTask) -> LoadPath:
    """Run one task (in a worker): height map, then the warm-started load path."""
    # A worker forked (by our pool or a user's) after its parent used torch's OpenMP threads
    # hangs in its first torch operation on several threads; the height map is the only
    # torch a task runs before the solve, which sets its own threads.
    with torch_threads(1):
        hm = height_map(task.design, task.grid)
    return solve_path(
        hm.heights,
        hm.cell_side,
        task.loads,
        hm.owner,
        task.design.n_asperities,
        tolerance=task.tolerance,
        max_iter=task.max_iter,
        first_index=task.first_index,
        total=task.total,
        fields=task.fields,
        engine=task.engine,
        device=task.device,
        threads=task.threads,
        contact_depth=task.contact_depth,
    )


def local_pool(workers: int) -> cf.ProcessPoolExecutor:
    """A pool of ``workers`` local processes (fork on Linux: they start in milliseconds)."""
    ctx = mp.get_context("fork" if sys.platform.startswith("linux") else "spawn")
    return cf.ProcessPoolExecutor(
        max_workers=workers,
        mp_context=ctx,
        initializer=die_with_parent,  # a killed sweep takes its workers with it
        initargs=(os.getpid(),),
    )


def stream(
    fn: Callable[[Any], Any],
    tasks: Sequence[Any],
    *,
    executor: cf.Executor | None = None,
    jobs: int = 1,
    on_done: Callable[[int, Any], Any],
    on_error: Callable[[int, BaseException], Any],
    retries: int = RETRIES,
) -> None:
    """Run ``fn(task)`` for every task; ``on_done(i, result)`` or ``on_error(i, exc)`` are
    called in this thread, in the order the tasks finish.

    executor: any ``concurrent.futures.Executor`` (left running); None: a pool of ``jobs``
    local processes owned here (none with jobs = 1: the tasks run in this process). A task
    that raises MetainterfaceError goes to ``on_error`` at once; one the engine lost is
    submitted again, at most ``retries`` times, then goes to ``on_error``. An exception from
    a callback stops the sweep (tasks not started are cancelled).
    """
    if not tasks:
        return
    if executor is None and jobs <= 1:
        for i, task in enumerate(tasks):
            try:
                result = fn(task)
            except MetainterfaceError as exc:
                on_error(i, exc)
                continue
            on_done(i, result)
        return
    own = executor is None
    pool = local_pool(min(jobs, len(tasks))) if executor is None else executor
    attempts = [0] * len(tasks)
    pending: dict[cf.Future[Any], int] = {}

    def submit(i: int) -> None:
        try:
            pending[pool.submit(fn, tasks[i])] = i
        except RuntimeError as exc:  # shut down or broken: nothing left to run on
            raise MetainterfaceError(
                f"the executor refused a task ({type(exc).__name__}: {exc}); "
                "run the sweep again to resume"
            ) from None

    finished = False
    try:
        for i in range(len(tasks)):
            submit(i)
        while pending:
            done, _ = cf.wait(list(pending), return_when=cf.FIRST_COMPLETED)
            lost: list[int] = []
            for fut in done:
                i = pending.pop(fut)
                try:
                    result = fut.result()
                except MetainterfaceError as exc:  # the task's own failure: no retry
                    on_error(i, exc)
                    continue
                except Exception as exc:  # the engine lost it (dead worker, broken pool)
                    attempts[i] += 1
                    if attempts[i] > retries:
                        on_error(
                            i,
                            MetainterfaceError(
                                f"task lost {attempts[i]} times, last by "
                                f"{type(exc).__name__}: {exc}".strip()
                            ),
                        )
                    else:
                        lost.append(i)
                    continue
                on_done(i, result)
            if own and lost and isinstance(pool, cf.ProcessPoolExecutor) and _broken(pool):
                # a dead process breaks a local pool whole: every task on it is lost
                lost += list(pending.values())
                pending.clear()
                pool.shutdown(wait=False, cancel_futures=True)
                pool = local_pool(min(jobs, len(lost)))
            for i in sorted(set(lost)):
                submit(i)
        finished = True
    finally:
        for fut in pending:
            fut.cancel()
        if own:  # interrupted: do not wait for the running solves
            pool.shutdown(wait=finished, cancel_futures=True)


def _broken(pool: cf.ProcessPoolExecutor) -> bool:
    try:
        pool.submit(int).cancel()
    except cf.BrokenExecutor:
        return True
    return False
