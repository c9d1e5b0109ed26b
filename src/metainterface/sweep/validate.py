"""Validation results on disk: one folder per design, and sweeps over many designs.

Each design's folder holds

    bem.csv          p_star,alpha_bem,alpha_model,rel_err,p_max,alpha_bem_pixels
    asperities.csv   p_star, bem_k and model_k: contact area of asperity k / A_nom
    models.csv       alpha and rel_err of every registered model (``validate`` only)
    fields.nc        optional, pressure, gap and contact mask at every load (xarray/NetCDF4,
                     ``metainterface.io.fields``); the figure's pressure panel reads it
    validation.png   optional, the paper's fig. 6 (``plots.plot_validation``)
    result.json      settings, summary errors and residuals; written last (completion mark)

A sweep (``validate_many``) writes each design's folder whole (built under a hidden name,
then renamed) and ``summary.csv``, one row per finished design, after each design.
"""

from __future__ import annotations

import collections
import contextlib
import csv
import hashlib
import io
import json
import os
import shutil
import uuid
from collections.abc import Sequence
from concurrent.futures import Executor
from pathlib import Path
from typing import Any

import numpy as np

from metainterface import _checks
from metainterface._files import (
    check_output_folder,
    csv_header,
    output_set,
    provenance,
    strict_json,
    write_columns,
    write_text,
)
from metainterface._names import DEFAULT_ENGINE
from metainterface.errors import MetainterfaceError
from metainterface.io.fields import FIELDS_FILE, open_fields, require_xarray, write_fields
from metainterface.physics.cell import Design
from metainterface.physics.models import ForwardModel, get_model
from metainterface.plots import plot_validation, save_figure
from metainterface.validation.bem import (
    MAX_ITER,
    TOLERANCE,
    LoadPath,
    available_cpus,
)
from metainterface.validation.cluster import check_scheduler, dask_executor
from metainterface.validation.engine import RETRIES, solve_task, stream
from metainterface.validation.engines import check_engine, get_engine
from metainterface.validation.validate import (
    DEFAULT_LOADS,
    ValidationPlan,
    ValidationResult,
    check_jobs,
    design_target,
    plan_validation,
    solve_batched,
    validation_request,
)


def validate(
    design: Design | str | os.PathLike[str],
    *,
    grid: int | None = None,
    loads: int | Sequence[float] | np.ndarray = DEFAULT_LOADS,
    p_max: float | None = None,
    model: str | ForwardModel | None = None,
    tolerance: float = TOLERANCE,
    max_iter: int = MAX_ITER,
    jobs: int | None = 1,
    progress: bool = False,
    out: str | os.PathLike[str] | None = None,
    fields: bool = False,
    executor: Executor | None = None,
    scheduler: str | None = None,
    engine: str = DEFAULT_ENGINE,
    device: str = "auto",
) -> ValidationResult:
    """Check a design against the boundary element method.

    Parameters
    ----------
    design : Design or path
        The design or a design file.
    grid : int
        Grid points per cell side, a multiple of n (default 256 n: 768 for N = 9).
    loads : int or list of float
        K loads uniform on (0, P*_max] (default 20), or explicit P* values.
    p_max : float
        The largest load P* when ``loads`` is a count (default P* at Delta_max).
    model : str or ForwardModel
        The forward model compared with (default ``"independent"``).
    tolerance, max_iter :
        Polonsky-Keer-Rey tolerance (default 1e-11) and iteration limit.
    jobs : int
        The load path is split into ``jobs`` warm-started chunks, run on as many local
        processes, or on ``executor`` / ``scheduler`` (None: the local cores).
    progress : bool
        Show a progress bar over the loads.
    out : path
        Also write bem.csv, asperities.csv, models.csv, validation.png, result.json there
        (and fields.nc with ``fields``).
    fields : bool
        Keep the pressure and gap fields of every load (``result.pressures``, ``.gaps``:
        (K, M, M)); with ``out``, write them as fields.nc (the ``fields`` extra).
    executor : concurrent.futures.Executor
        Run the chunks there, e.g. ``dask.distributed.Client(...).get_executor()``.
    scheduler : str
        Or a Dask scheduler: ``"tcp://HOST:PORT"`` to join a running cluster, ``"local"`` to
        start a LocalCluster of ``jobs`` processes (the ``distributed`` extra).
    engine : str
        The contact solver: ``"torch"`` (default; the base install, CPU threads or a GPU)
        or ``"tamaas"`` (the ``bem`` extra, CPU; the reference).
    device : str
        Where the torch engine solves: ``"auto"`` (a CUDA device if torch sees one, else
        the CPU), ``"cpu"``, ``"cuda"`` or ``"cuda:N"``.

    Returns
    -------
    ValidationResult
        numpy ``p_star``, ``alpha_bem``, ``alpha_model``, ``rel_err`` (K,), and summaries
        (``max_rel_err_upper``, ``target_errors()``).
    """
    check_engine(engine, device)
    if out is not None:  # before the solve: a bad folder should not cost a BEM run
        check_output_folder(out)
    if fields and out is not None:
        require_xarray()  # before the solve, not after it
    if executor is not None and scheduler is not None:
        raise MetainterfaceError("give executor or scheduler, not both")
    if scheduler is not None:
        check_scheduler(scheduler)
    name = str(design) if isinstance(design, str | os.PathLike) else "design"
    if not isinstance(design, Design):
        if not isinstance(design, str | os.PathLike):
            raise MetainterfaceError("design must be a Design or a design file path")
        design = Design.load(design)
    fm = get_model(model)
    if p_max is not None:
        k = _checks.whole("loads", loads, low=1, high=10_000)
        p_max = _checks.number("p_max", p_max, low=0.0, low_open=True)
        top = fm.model_curve(design).p_star_max
        if p_max > top * (1 + 1e-12):
            raise MetainterfaceError(
                f"p_max {p_max:g} is beyond what the design reaches at Delta_max "
                f"(P*_max = {top:.6g}); allowed range (0, {top:.6g}]"
            )
        loads = [p_max * i / k for i in range(1, k + 1)]
    plan = plan_validation(
        design,
        grid,
        loads,
        name=name,
        model=fm,
        tolerance=tolerance,
        max_iter=max_iter,
        engine=engine,
        device=device,
    )
    n_loads = len(plan.loads)
    jobs = min(available_cpus(), n_loads) if jobs is None else check_jobs(jobs)
    with contextlib.ExitStack() as stack:
        if scheduler is not None:
            executor = stack.enter_context(dask_executor(scheduler, jobs))
        bar = None
        if progress:
            from tqdm.auto import tqdm

            bar = stack.enter_context(tqdm(total=n_loads, desc="BEM loads", unit="load"))
        result = plan.solve(
            jobs,
            progress=None if bar is None else bar.update,
            executor=executor,
            fields=fields,
        )
    if out is not None:
        with output_set():  # all of a result's files, or none
            write_result(result, out, command="validate", jobs=jobs)
            write_models(result, Path(out) / "models.csv")
    return result


def write_models(result: ValidationResult, path: Path) -> dict[str, np.ndarray]:
    """alpha and rel_err of every registered model at the result's loads, as a CSV; returns
    {model: rel_err (K,)}."""
    both = result.alpha_by_model
    rel = {name: result.alpha_bem / alpha - 1.0 for name, alpha in both.items()}
    columns = {"p_star": result.p_star, "alpha_bem": result.alpha_bem}
    columns |= {f"alpha_{name}": alpha for name, alpha in both.items()}
    columns |= {f"rel_err_{name}": r for name, r in rel.items()}
    write_columns(
        path,
        columns,
        command="validate",
        design=result.name,
        grid=result.grid,
        loads_from=result.model.label,
    )
    return rel


def result_settings(result: ValidationResult, **extra: Any) -> dict[str, Any]:
    """The settings recorded with a result's files."""
    return {
        "design": result.design.to_dict(),
        "grid": result.grid,
        "loads": [float(p) for p in result.p_star],
        "model": result.model.label,
        "tolerance": result.tolerance,
        "max_iter": result.max_iter,
        "engine": result.engine,
        "solver": get_engine(result.engine).solver,
        **extra,
    }


@output_set()  # a design's files go out together (a sweep resumes design by design)
def write_result(
    result: ValidationResult, out_dir: str | os.PathLike[str], *, figure: bool = True, **extra: Any
) -> Path:
    """Write bem.csv, asperities.csv, (fields.nc, validation.png) and result.json into
    ``out_dir``; fields.nc when the result carries fields (solved with ``fields=True``)."""
    out = Path(out_dir)
    settings = result_settings(result, **extra)
    fields = None
    if result.pressures is not None:
        write_fields(result, out / FIELDS_FILE, **settings)
        fields = open_fields(out / FIELDS_FILE)  # the figure shows what the file holds
    write_columns(
        out / "bem.csv",
        {
            "p_star": result.p_star,
            "alpha_bem": result.alpha_bem,
            "alpha_model": result.alpha_model,
            "rel_err": result.rel_err,
            "p_max": result.p_max,
            "alpha_bem_pixels": result.alpha_bem_pixels,
        },
        **settings,
    )
    cols: dict[str, np.ndarray] = {"p_star": result.p_star}
    for k in range(result.design.n_asperities):
        cols[f"bem_{k}"] = result.asperity_alpha_bem[:, k]
    if result.asperity_alpha_model is not None:
        for k in range(result.design.n_asperities):
            cols[f"model_{k}"] = result.asperity_alpha_model[:, k]
    write_columns(out / "asperities.csv", cols, **settings)
    if figure:
        fig = plot_validation(
            result, target=design_target(result.design), title=result.name, fields=fields
        )
        save_figure(fig, out / "validation.png", **settings)
    request = validation_request(
        result.design,
        result.grid,
        result.p_star,
        result.model,
        result.tolerance,
        result.max_iter,
        engine=result.engine,
    )
    record = {
        "request": request,
        "request_hash": request_hash(request),
        "fields": result.pressures is not None,
        "summary": result.summary(),
        "residual": [float(r) for r in result.residual],
        "seconds": [float(s) for s in result.seconds],
        "provenance": provenance(**settings),
    }
    write_text(out / "result.json", strict_json.dumps(record, indent=2) + "\n")
    return out


def request_hash(request: dict[str, Any]) -> str:
    """A short hash of a validation request (JSON with sorted keys): what a resumed sweep
    compares to know a stored result was made with the same settings."""
    text = json.dumps(request, sort_keys=True, separators=(",", ":"))
    return hashlib.sha256(text.encode("utf-8")).hexdigest()[:16]


# --- many designs ------------------------------------------------------------------------

#: Columns of summary.csv, one row per design.
SUMMARY_COLUMNS = (
    "name",
    "status",
    "max_rel_err_upper_half",
    "target_error_bem",
    "target_error_model",
    "error",
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


def _swap_in(staging: Path, final: Path) -> None:
    """Put a finished folder in place of ``final`` (two renames, no half-written folder)."""
    if final.exists():
        old = final.with_name(f".{final.name}.old-{uuid.uuid4().hex[:8]}")
        os.replace(final, old)
        os.replace(staging, final)
        shutil.rmtree(old, ignore_errors=True)
    else:
        os.replace(staging, final)


def _staging(out: Path, name: str) -> Path:
    return out / f".{name}.partial-{uuid.uuid4().hex[:8]}"


def _clear_leftovers(out: Path) -> None:
    """Remove what a sweep killed while writing leaves: hidden design folders, and the
    temporary files of summary.csv / summary.json (``atomic_open``'s ``.NAME.*.tmp``)."""
    if out.is_dir():
        for leftover in [*out.glob(".*.partial-*"), *out.glob(".*.old-*")]:
            shutil.rmtree(leftover, ignore_errors=True)
        for name in ("summary.csv", "summary.json"):
            for tmp in out.glob(f".{name}.*.tmp"):
                tmp.unlink(missing_ok=True)


def summary_row(name: str, summary: dict[str, Any]) -> dict[str, Any]:
    """One row of summary.csv: name, status (ok / failed), the largest relative error over
    the upper half of the loads, the target errors (BEM, model; blank without a target),
    the error message of a failed design."""
    if "error" in summary:
        return {"name": name, "status": "failed", "error": summary["error"]}
    return {
        "name": name,
        "status": "ok",
        "max_rel_err_upper_half": summary.get("max_rel_err_upper_half"),
        "target_error_bem": summary.get("target_error_bem"),
        "target_error_model": summary.get("target_error_model"),
    }


def _cell(value: Any) -> Any:
    if value is None:
        return ""
    return repr(float(value)) if isinstance(value, float) else value  # repr: exact floats


def _write_summary(out: Path, rows: list[dict[str, Any]], **settings: Any) -> None:
    buf = io.StringIO()
    buf.write(csv_header(**settings))
    writer = csv.DictWriter(buf, SUMMARY_COLUMNS, lineterminator="\n")
    writer.writeheader()
    for row in rows:
        cells = {k: _cell(v) for k, v in row.items()}
        # '#' starts a comment for pandas.read_csv(comment="#"): keep messages readable there
        cells["error"] = str(cells.get("error", "")).replace("#", "no.").replace("\n", " ")
        writer.writerow(cells)
    write_text(out / "summary.csv", buf.getvalue())


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
    jobs = available_cpus() if jobs is None else check_jobs(jobs)
    if executor is None and scheduler is None and solver.name == "torch" and jobs > 1:
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
    here = executor is None and scheduler is None and chunks == 1 and solver.name == "torch"
    if batch is not None:
        batch = _checks.whole("batch", batch, low=1, high=1024)
        if batch > 1 and not here:
            raise MetainterfaceError(
                "batch > 1 needs engine='torch' solving in this process (no executor or "
                "scheduler, chunks=1)",
                argument="batch",
            )
    out = Path(out_dir)
    items = _design_list(designs)
    summaries: dict[str, dict[str, Any]] = {}
    todo: list[ValidationPlan] = []
    for name, design in items:
        try:
            prep = plan_validation(
                design,
                name=name,
                grid=grid,
                loads=loads,
                model=model,
                tolerance=tolerance,
                max_iter=max_iter,
                engine=engine,
                device=device,
            )
        except MetainterfaceError as exc:
            raise MetainterfaceError(f"{name}: {exc}") from None
        done = _stored(out / name, prep.request(), fields, figures)
        if done is not None:
            summaries[name] = done
        else:
            todo.append(prep)
    _clear_leftovers(out)
    sweep = {
        "command": "validate_many",
        "grid": grid,
        "loads": loads if isinstance(loads, int) else [float(p) for p in loads],
        "model": get_model(model).label,
        "tolerance": tolerance,
        "max_iter": max_iter,
        "engine": get_engine(engine).name,
    }

    def write_summary() -> None:
        ordered = {n: summaries[n] for n, _ in items if n in summaries}
        _write_summary(out, [summary_row(n, s) for n, s in ordered.items()], **sweep)
        record = {"designs": ordered, "provenance": provenance(**sweep)}
        write_text(out / "summary.json", strict_json.dumps(record, indent=2) + "\n")

    # one design's chunks: (design index in todo, its tasks); flat list for the engine
    tasks, owner = [], []
    # in this process (no executor, one job) torch keeps its threads; workers run on one
    threads = None if executor is None and scheduler is None and jobs <= 1 else 1
    for d, prep in enumerate(todo):
        for task in prep.tasks(chunks, fields=fields, threads=threads):
            tasks.append(task)
            owner.append(d)
    parts: dict[int, dict[int, LoadPath]] = {d: {} for d in range(len(todo))}
    failed: set[int] = set()
    n_chunks = collections.Counter(owner)

    bar: Any = None

    def on_done(i: int, part: LoadPath) -> None:
        d = owner[i]
        if d in failed:
            return
        parts[d][i] = part
        if len(parts[d]) < n_chunks[d]:
            return
        prep = todo[d]
        path = LoadPath.concat([parts[d][j] for j in sorted(parts[d])])
        parts[d].clear()
        result = prep.result(path)
        staging = _staging(out, prep.name)
        write_result(result, staging, figure=figures, command="validate_many")
        _swap_in(staging, out / prep.name)
        summaries[prep.name] = result.summary()
        write_summary()
        if bar is not None:
            bar.update(1)

    def on_error(i: int, exc: BaseException) -> None:
        d = owner[i]
        if d in failed:
            return
        failed.add(d)
        parts[d].clear()
        prep = todo[d]
        staging = _staging(out, prep.name)
        write_text(staging / "error.txt", f"{exc}\n")
        _swap_in(staging, out / prep.name)
        summaries[prep.name] = {"name": prep.name, "error": str(exc)}
        write_summary()
        if bar is not None:
            bar.update(1)

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

            bar = stack.enter_context(tqdm(total=len(todo), desc="designs", unit="design"))
        if batch > 1:  # one task per design: task i is design i
            solve_batched(todo, batch, fields=fields, on_done=on_done, on_error=on_error)
        else:
            stream(
                solve_task,
                tasks,
                executor=executor,
                jobs=jobs,
                on_done=on_done,
                on_error=on_error,
                retries=retries,
            )
    write_summary()
    return {n: summaries[n] for n, _ in items}
