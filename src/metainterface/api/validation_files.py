"""Validation results on disk: one folder per design, and sweeps over many designs.

Each design's folder holds

    bem.csv          p_star,alpha_bem,alpha_model,rel_err,p_max,alpha_bem_pixels
    asperities.csv   p_star, bem_k and model_k: contact area of asperity k / A_nom
    validation.png   optional, the paper's fig. 6 (``plots.plot_validation``)
    result.json      settings, summary errors and residuals; written last (completion mark)
"""

from __future__ import annotations

import json
import os
from collections.abc import Sequence
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
from metainterface.errors import MetainterfaceError
from metainterface.physics.cell import Design
from metainterface.physics.models import ForwardModel, get_model
from metainterface.plots import plot_validation, save_figure
from metainterface.validation.bem import (
    MAX_ITER,
    TOLERANCE,
    LoadPath,
    available_cpus,
    require_tamaas,
    run_tasks,
)
from metainterface.validation.validate import (
    DEFAULT_LOADS,
    ValidationPlan,
    ValidationResult,
    check_jobs,
    design_target,
    plan_validation,
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
) -> ValidationResult:
    """Check a design against the boundary element method (Tamaas, the ``bem`` extra).

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
        Processes; the load path is split into warm-started chunks (None: the cores).
    progress : bool
        Show a progress bar over the loads.
    out : path
        Also write bem.csv, asperities.csv, models.csv, validation.png, result.json there.

    Returns
    -------
    ValidationResult
        numpy ``p_star``, ``alpha_bem``, ``alpha_model``, ``rel_err`` (K,), and summaries
        (``max_rel_err_upper``, ``target_errors()``).
    """
    require_tamaas()
    if out is not None:  # before the solve: a bad folder should not cost a BEM run
        check_output_folder(out)
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
        design, grid, loads, name=name, model=fm, tolerance=tolerance, max_iter=max_iter
    )
    n_loads = len(plan.loads)
    jobs = min(available_cpus(), n_loads) if jobs is None else check_jobs(jobs)
    if progress:
        from tqdm.auto import tqdm

        with tqdm(total=n_loads, desc="BEM loads", unit="load") as bar:
            result = plan.solve(jobs, progress=bar.update)
    else:
        result = plan.solve(jobs)
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
        "solver": "tamaas PolonskyKeerRey, basic_2d, E* = 1",
        **extra,
    }


@output_set()  # a design's files go out together (a sweep resumes design by design)
def write_result(
    result: ValidationResult, out_dir: str | os.PathLike[str], *, figure: bool = True, **extra: Any
) -> Path:
    """Write bem.csv, asperities.csv, (validation.png) and result.json into ``out_dir``."""
    out = Path(out_dir)
    settings = result_settings(result, **extra)
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
        fig = plot_validation(result, target=design_target(result.design), title=result.name)
        save_figure(fig, out / "validation.png", **settings)
    record = {
        "request": validation_request(
            result.design,
            result.grid,
            result.p_star,
            result.model,
            result.tolerance,
            result.max_iter,
        ),
        "summary": result.summary(),
        "residual": [float(r) for r in result.residual],
        "seconds": [float(s) for s in result.seconds],
        "provenance": provenance(**settings),
    }
    write_text(out / "result.json", strict_json.dumps(record, indent=2) + "\n")
    return out


# --- many designs ------------------------------------------------------------------------


def _design_list(designs: Sequence[str | os.PathLike[str] | Design] | str | os.PathLike[str]):
    """[(name, Design)] from a folder of *.json, a list of files, or Design objects."""
    if isinstance(designs, str | os.PathLike):
        folder = Path(designs)
        if not folder.is_dir():
            raise MetainterfaceError(f"{folder}: not a folder of design files")
        files = sorted(folder.glob("*.json"))
        if not files:
            raise MetainterfaceError(f"{folder}: no design files (*.json) in it")
        designs = files
    out: list[tuple[str, Design]] = []
    for i, item in enumerate(designs):
        if isinstance(item, Design):
            out.append((f"design_{i:04d}", item))
        else:
            out.append((Path(item).stem, Design.load(item)))
    names = [n for n, _ in out]
    dup = sorted({n for n in names if names.count(n) > 1})
    if dup:
        raise MetainterfaceError(f"design names must be unique, repeated: {', '.join(dup)}")
    return out


def _stored(folder: Path, request: dict[str, Any]) -> dict[str, Any] | None:
    try:
        record = json.loads((folder / "result.json").read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    if record.get("request") != request:
        return None
    return record.get("summary")


def validate_many(
    designs: Sequence[str | os.PathLike[str] | Design] | str | os.PathLike[str],
    out_dir: str | os.PathLike[str],
    *,
    grid: int | None = None,
    loads: int | Sequence[float] | np.ndarray = DEFAULT_LOADS,
    jobs: int = 1,
    model: str | ForwardModel | None = None,
    tolerance: float = TOLERANCE,
    max_iter: int = MAX_ITER,
    figures: bool = False,
    progress: bool = True,
) -> dict[str, dict[str, Any]]:
    """Validate many designs (a folder of design files, a list of files or Designs).

    Each design's results go to ``out_dir/<name>/`` (see ``write_result``) as soon as it is
    done, one design per process with ``jobs > 1``. A design whose result.json records the
    same request (design, grid, loads, model, solver settings) is skipped, so an
    interrupted sweep resumes where it stopped. A design that fails (e.g. no convergence)
    gets ``error.txt`` and the sweep goes on. ``out_dir/summary.json`` lists every design.
    Returns {name: summary} (summary has an "error" key for failed designs).
    """
    require_tamaas()
    jobs = check_jobs(jobs)
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
            )
        except MetainterfaceError as exc:
            raise MetainterfaceError(f"{name}: {exc}") from None
        done = _stored(out / name, prep.request())
        if done is not None:
            summaries[name] = done
        else:
            todo.append(prep)

    bar = None
    if progress and todo:
        from tqdm.auto import tqdm

        bar = tqdm(total=len(todo), desc="designs", unit="design")

    def write_summary() -> None:
        ordered = {n: summaries[n] for n, _ in items if n in summaries}
        write_text(
            out / "summary.json",
            strict_json.dumps(
                {"designs": ordered, "provenance": provenance(command="validate_many")}, indent=2
            )
            + "\n",
        )

    def on_done(i: int, path: LoadPath) -> None:
        prep = todo[i]
        result = prep.result(path)
        folder = out / prep.name
        (folder / "error.txt").unlink(missing_ok=True)
        write_result(result, folder, figure=figures, command="validate_many")
        summaries[prep.name] = result.summary()
        write_summary()
        if bar is not None:
            bar.update(1)

    def on_error(i: int, exc: BaseException) -> None:
        prep = todo[i]
        write_text(out / prep.name / "error.txt", f"{exc}\n")
        summaries[prep.name] = {"name": prep.name, "error": str(exc)}
        write_summary()
        if bar is not None:
            bar.update(1)

    try:
        # tasks are built (height maps computed) only as processes take them
        run_tasks([p.task for p in todo], jobs, on_done=on_done, on_error=on_error)
    finally:
        if bar is not None:
            bar.close()
    write_summary()
    return {n: summaries[n] for n, _ in items}
