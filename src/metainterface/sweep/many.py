"""A BEM sweep over many designs (:func:`validate_many`): the designs listed and planned,
finished ones with the same request kept, the rest solved on local processes, a Dask
cluster or an executor (their folders and summary.csv written by ``sweep.collect``)."""

from __future__ import annotations

import contextlib
import json
import os
import shutil
from collections.abc import Sequence
from concurrent.futures import Executor
from pathlib import Path
from typing import Any

import numpy as np

from metainterface import _checks
from metainterface._names import DEFAULT_ENGINE
from metainterface._threads import uses_threads
from metainterface.errors import MetainterfaceError
from metainterface.io.fields import FIELDS_FILE, require_xarray
from metainterface.physics.cell import Design
from metainterface.physics.models import ForwardModel
from metainterface.physics.registry import get_model
from metainterface.sweep.collect import Collector
from metainterface.sweep.folders import request_hash, warn_adhesive
from metainterface.validation.batched import solve_batched
from metainterface.validation.bem import (
    MAX_ITER,
    TOLERANCE,
    available_cpus,
)
from metainterface.validation.cluster import check_scheduler, dask_executor
from metainterface.validation.executors import RETRIES, solve_task, stream
from metainterface.validation.solvers import check_engine, get_engine
from metainterface.validation.validate import (
    DEFAULT_LOADS,
    ValidationPlan,
    check_jobs,
    plan_validation,
)


def _design_list(designs: Sequence[str | os.PathLike[str] | Design] | str | os.PathLike[str]):
    """[(name, Design)] from a folder of *.json, a list of files, or Design objects."""
    if isinstance(designs, str | os.PathLike):
        folder = Path(designs)
        if not folder.is_dir():
            raise MetainterfaceError(f"{folder}: not a folder of design files")
        # design files in it, or the result folders `design` writes (one design.json each)
        files = sorted(folder.glob("*.json")) or sorted(folder.glob("*/design.json"))
        if not files:
            raise MetainterfaceError(f"{folder}: no design files (*.json or */design.json) in it")
        designs = files
    items = list(designs)
    labels = _file_labels([Path(d) for d in items if not isinstance(d, Design)])
    out: list[tuple[str, Design]] = []
    for i, item in enumerate(items):
        if isinstance(item, Design):
            out.append((f"design_{i:04d}", item))
        else:
            out.append((labels[Path(item)], Design.load(item)))
    if not out:
        raise MetainterfaceError("designs: no designs given")
    names = [n for n, _ in out]
    dup = sorted({n for n in names if names.count(n) > 1})
    if dup:
        raise MetainterfaceError(f"design names must be unique, repeated: {', '.join(dup)}")
    return out


def _file_labels(paths: list[Path]) -> dict[Path, str]:
    """A result name per design file: its stem, or its folder for the ``design.json`` that
    ``design`` writes; where names collide, as many parent folders as make them distinct."""

    def label(p: Path, depth: int) -> str:
        parents = p.resolve().parent.parts[1:]
        depth = max(depth, 1) if p.stem == "design" else depth
        parts = list(parents[len(parents) - depth :]) if depth else []
        return "-".join(parts if p.stem == "design" and parts else [*parts, p.stem])

    depth = dict.fromkeys(paths, 0)
    for _ in range(max((len(p.resolve().parts) for p in depth), default=0)):
        names = {p: label(p, d) for p, d in depth.items()}
        clash = [p for p, n in names.items() if list(names.values()).count(n) > 1]
        if not clash:
            break
        for p in clash:  # only the colliding names grow
            depth[p] += 1
    return {p: label(p, d) for p, d in depth.items()}


def _stored(folder: Path, request: dict[str, Any], fields: bool, figure: bool) -> dict | None:
    """The summary of a finished result made with the same settings (and the files asked
    for), or None."""
    try:
        record = json.loads((folder / "result.json").read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    stored = record.get("request")
    if isinstance(stored, dict) and "engine" not in stored and request.get("engine") == "tamaas":
        # results written before there were engines were Tamaas's
        request = {k: v for k, v in request.items() if k != "engine"}
    if record.get("request_hash") != request_hash(request) or record.get("request") != request:
        return None
    if fields and not (folder / FIELDS_FILE).exists():
        return None
    if figure and not (folder / "validation.png").exists():
        return None
    return record.get("summary")


def _clear_leftovers(out: Path) -> None:
    """Remove what a sweep killed while writing leaves: hidden design folders, and the
    temporary files of summary.csv / summary.json (``atomic_open``'s ``.NAME.*.tmp``)."""
    if out.is_dir():
        for leftover in [*out.glob(".*.partial-*"), *out.glob(".*.old-*")]:
            shutil.rmtree(leftover, ignore_errors=True)
        for name in ("summary.csv", "summary.json"):
            for tmp in out.glob(f".{name}.*.tmp"):
                tmp.unlink(missing_ok=True)


@uses_threads()
def validate_many(
    designs: Sequence[str | os.PathLike[str] | Design] | str | os.PathLike[str],
    out_dir: str | os.PathLike[str],
    *,
    grid: int | None = None,
    loads: int | Sequence[float] | np.ndarray = DEFAULT_LOADS,
    jobs: int | None = 1,
    model: str | ForwardModel | None = None,
    tolerance: float = TOLERANCE,
    max_iter: int = MAX_ITER,
    figures: bool = False,
    fields: bool = False,
    chunks: int = 1,
    executor: Executor | None = None,
    scheduler: str | None = None,
    retries: int = RETRIES,
    progress: bool = True,
    engine: str = DEFAULT_ENGINE,
    device: str = "auto",
    batch: int | None = None,
) -> dict[str, dict[str, Any]]:
    """Validate many designs against BEM, on local processes or any executor.

    Parameters
    ----------
    designs : folder, list of paths or Designs
        A folder of design files (``*.json``, or the ``*/design.json`` that ``design``
        writes), a list of files, or Design objects (named ``design_0000``, ...). A file is
        named by its stem, a ``design.json`` by its folder; colliding names take more of
        their path.
    out_dir : path
        Each design's results go to ``out_dir/<name>/`` (see ``write_result``), written
        whole as soon as it is done; ``out_dir/summary.csv`` (columns ``SUMMARY_COLUMNS``)
        and ``summary.json`` are rewritten after each design.
    grid, loads, model, tolerance, max_iter :
        As in ``validate``, for every design.
    jobs : int
        Local processes (default 1: in this process; None: the cores), or the workers of
        ``scheduler="local"``.
    figures, fields : bool
        Also write validation.png / fields.nc for every design.
    chunks : int
        Split each design's load path into this many warm-started tasks (for fewer designs
        than workers); default one task per design.
    executor : concurrent.futures.Executor
        Run the tasks there: ``dask.distributed.Client(...).get_executor()``,
        ``mpi4py.futures.MPIPoolExecutor()``, a dask-jobqueue cluster's client, ...
    scheduler : str
        Or a Dask scheduler: ``"tcp://HOST:PORT"`` joins a running cluster, ``"local"``
        starts a LocalCluster of ``jobs`` processes (the ``distributed`` extra).
    retries : int
        Times a task lost by the engine (a worker that died) is submitted again.
    progress : bool
        A progress bar over the designs.
    engine, device : str
        The contact solver and where torch runs, as in ``validate``. The engine is part of
        each stored request: a sweep resumed with another engine solves its designs again.
    batch : int
        Designs of one grid size the torch engine solves together, in this process (no
        executor, ``chunks=1``). Default: as many as a GPU's memory holds on a GPU, 1 on the
        CPU (where a batch is no faster).

    Returns
    -------
    dict
        {name: summary}; a failed design's summary has an "error" key (and its folder an
        error.txt).

    Notes
    -----
    A design whose result.json records the same request (design, grid, loads, model,
    solver settings; compared by hash) and has the files asked for is skipped, so a sweep
    that was interrupted, or that lost its engine, resumes where it stopped. A design that
    fails (e.g. no convergence) gets error.txt and the sweep goes on; it is tried again on
    the next run.
    """
    solver = check_engine(engine, device)
    jobs, chunks, retries, batch, here = _check_run(
        solver.name, jobs, chunks, retries, executor, scheduler, device, fields, batch
    )
    out = Path(out_dir)
    items = _design_list(designs)
    warn_adhesive(items, get_model(model))
    plan = dict(grid=grid, loads=loads, model=model, tolerance=tolerance, max_iter=max_iter)
    summaries, todo = _plan(items, out, plan, engine, device, fields, figures)
    _clear_leftovers(out)
    settings = {
        "command": "validate_many",
        "grid": grid,
        "loads": loads if isinstance(loads, int) else [float(p) for p in loads],
        "model": get_model(model).label,
        "tolerance": tolerance,
        "max_iter": max_iter,
        "engine": get_engine(engine).name,
    }
    # one design's chunks: (design index in todo, its tasks); flat list for the engine
    tasks, owner = [], []
    # in this process (no executor, one job) torch keeps its threads; workers run on one
    threads = None if executor is None and scheduler is None and jobs <= 1 else 1
    for d, prep in enumerate(todo):
        for task in prep.tasks(chunks, fields=fields, threads=threads):
            tasks.append(task)
            owner.append(d)
    sink = Collector(out, items, summaries, todo, owner, settings, figures)
    if batch is None:
        batch = 1
        if here and todo:
            from metainterface._device import resolve_device
            from metainterface.validation.torch_bem import batch_size

            batch = batch_size(todo[0].grid, resolve_device(device))
    with contextlib.ExitStack() as stack:
        if scheduler is not None and tasks:  # joined first: a bad address fails before the bar
            executor = stack.enter_context(dask_executor(scheduler, jobs))
        if progress and todo:
            from tqdm.auto import tqdm

            sink.bar = stack.enter_context(tqdm(total=len(todo), desc="designs", unit="design"))
        if batch > 1:  # one task per design: task i is design i
            solve_batched(todo, batch, fields=fields, on_done=sink.on_done, on_error=sink.on_error)
        else:
            stream(
                solve_task,
                tasks,
                executor=executor,
                jobs=jobs,
                on_done=sink.on_done,
                on_error=sink.on_error,
                retries=retries,
            )
    sink.write_summary()
    return {n: summaries[n] for n, _ in items}


def _check_run(
    solver: str,
    jobs: int | None,
    chunks: int,
    retries: int,
    executor: Executor | None,
    scheduler: str | None,
    device: str,
    fields: bool,
    batch: int | None,
) -> tuple[int, int, int, int | None, bool]:
    """validate_many's run settings checked: (jobs, chunks, retries, batch, here), where
    ``here``: the torch engine solving in this process (no executor or scheduler, one
    chunk a design), the one case where a batch of designs may be solved together."""
    jobs = available_cpus() if jobs is None else check_jobs(jobs)
    if executor is None and scheduler is None and solver == "torch" and jobs > 1:
        from metainterface._device import resolve_device

        if resolve_device(device).type == "cuda":
            jobs = 1  # one process drives the GPU (a forked child cannot use CUDA)
    chunks = _checks.whole("chunks", chunks, low=1, high=10_000)
    retries = _checks.whole("retries", retries, low=0, high=100)
    if fields:
        require_xarray()
    if executor is not None and scheduler is not None:
        raise MetainterfaceError("give executor or scheduler, not both")
    if scheduler is not None:
        check_scheduler(scheduler)
    here = executor is None and scheduler is None and chunks == 1 and solver == "torch"
    if batch is not None:
        batch = _checks.whole("batch", batch, low=1, high=1024)
        if batch > 1 and not here:
            raise MetainterfaceError(
                "batch > 1 needs engine='torch' solving in this process (no executor or "
                "scheduler, chunks=1)",
                argument="batch",
            )
    return jobs, chunks, retries, batch, here


def _plan(
    items: list[tuple[str, Design]],
    out: Path,
    plan: dict[str, Any],
    engine: str,
    device: str,
    fields: bool,
    figures: bool,
) -> tuple[dict[str, dict[str, Any]], list[ValidationPlan]]:
    """(summaries kept, plans to solve): each design planned with ``plan``'s settings; one
    whose folder holds a finished result of the same request (and the files asked for) is
    kept, not solved again. A design that cannot be planned is an error naming it."""
    summaries: dict[str, dict[str, Any]] = {}
    todo: list[ValidationPlan] = []
    for name, design in items:
        try:
            prep = plan_validation(design, name=name, engine=engine, device=device, **plan)
        except MetainterfaceError as exc:
            raise MetainterfaceError(f"{name}: {exc}") from None
        done = _stored(out / name, prep.request(), fields, figures)
        if done is not None:
            summaries[name] = done
        else:
            todo.append(prep)
    return summaries, todo
