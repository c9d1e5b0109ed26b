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

import contextlib
import hashlib
import json
import os
import warnings
from collections.abc import Sequence
from concurrent.futures import Executor
from pathlib import Path
from typing import Any

import numpy as np

from metainterface import _checks
from metainterface._files import (
    check_output_folder,
    output_set,
    provenance,
    strict_json,
    write_columns,
    write_text,
)
from metainterface._names import DEFAULT_ENGINE
from metainterface._threads import uses_threads
from metainterface.errors import MetainterfaceError
from metainterface.io.fields import FIELDS_FILE, open_fields, require_xarray, write_fields
from metainterface.physics.cell import Design
from metainterface.physics.models import ForwardModel
from metainterface.physics.registry import get_model
from metainterface.plots import plot_validation, save_figure
from metainterface.validation.adhesive_validate import is_adhesive, validate_adhesive
from metainterface.validation.bem import (
    MAX_ITER,
    TOLERANCE,
    available_cpus,
)
from metainterface.validation.cluster import check_scheduler, dask_executor
from metainterface.validation.result import ValidationResult, design_target
from metainterface.validation.solvers import check_engine, get_engine
from metainterface.validation.validate import (
    DEFAULT_LOADS,
    check_jobs,
    plan_validation,
    validation_request,
)


@uses_threads()
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
    sticky = is_adhesive(design, None if model is None else fm)
    if sticky is not None:  # the adhesive BEM against the adhesive model
        return _validate_adhesive(design, sticky, grid, loads, p_max, name, out, engine, device)
    warn_adhesive([(name, design)], fm)
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


def _validate_adhesive(
    design: Design,
    model: ForwardModel,
    grid: int | None,
    loads: Any,
    p_max: float | None,
    name: str,
    out: str | os.PathLike[str] | None,
    engine: str,
    device: str,
) -> ValidationResult:
    """``validate`` of a design with adhesion (``validation.adhesive_validate``): by
    approach, so ``loads`` is a count; the torch engine (the JKR-limit solver's)."""
    if not isinstance(loads, int | np.integer) or isinstance(loads, bool):
        raise MetainterfaceError(
            "an adhesive design is validated by approach (its loads are where the rising "
            "branch lands): give loads as a count",
            argument="loads",
        )
    if engine != "torch":
        warnings.warn(f"the adhesive BEM runs in the torch engine, not {engine}", stacklevel=3)
    result = validate_adhesive(
        design, model, grid=grid, loads=int(loads), p_max=p_max, name=name, device=device
    )
    if out is not None:
        with output_set():
            write_result(result, out, command="validate", jobs=1)
    return result


def warn_adhesive(items: list[tuple[str, Design]], model: ForwardModel) -> None:
    """Say once that the designs (name, Design) made with an adhesive model (design.json's
    "model") are solved here without adhesion, against ``model``."""
    if model.adhesion:  # refused by the plan, in its own words
        return
    made = [(n, d.extras.get("model")) for n, d in items]
    sticky = [(n, m) for n, m in made if isinstance(m, str) and _adhesive(m)]
    if not sticky:
        return
    what = (
        f"{sticky[0][0]} was designed with the adhesive model {sticky[0][1]}"
        if len(sticky) == 1
        else f"{len(sticky)} designs were designed with adhesive models ({sticky[0][0]}, ...)"
    )
    warnings.warn(
        f"{what}; validate solves the contact without adhesion, against the {model.label} "
        "model (design's check is the adhesive one)",
        stacklevel=3,
    )


def _adhesive(label: str) -> bool:
    """Whether a design file's model label names a model with adhesion."""
    try:
        return bool(get_model(label).adhesion)
    except MetainterfaceError:  # a model of another session's registry: not ours to judge
        return False


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
