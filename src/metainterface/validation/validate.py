"""Validate designs against BEM: one design (``validate_design``) or a sweep (``validate_many``).

For each design: the height map (``heightmap``), a BEM load path of K ascending mean
pressures (``bem``) and the forward model at the same P* (``models``, interpolated on its
exact Delta sweep). Results are written by ``write_result`` into one folder per design:

    bem.csv          p_star,alpha_bem,alpha_model,rel_err,p_max,alpha_bem_pixels
    asperities.csv   p_star, bem_k and model_k: contact area of asperity k / A_nom
    result.json      settings, summary errors and residuals; written last (completion mark)
    validation.png   optional, the paper's fig. 6 (``metainterface.plots.plot_validation``)

rel_err = alpha_bem / alpha_model - 1 (signed). Everything is dimensionless (E* = 1).
alpha_bem places the contact edges to sub-pixel accuracy (``bem.contact_area``);
alpha_bem_pixels is the plain count of grid points in contact, a few % high on coarse grids.
"""

from __future__ import annotations

import json
import os
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from metainterface.errors import MetainterfaceError
from metainterface.io.atomic import write_text
from metainterface.io.csvfiles import write_columns
from metainterface.io.design_file import design_to_dict, load_design
from metainterface.io.provenance import provenance
from metainterface.physics.cell import Design
from metainterface.validation.bem import (
    MAX_ITER,
    TOLERANCE,
    LoadPath,
    require_tamaas,
    run_tasks,
    solve_loads,
)
from metainterface.validation.heightmap import HeightMap, check_grid, default_grid, height_map
from metainterface.validation.models import ModelCurve, model_curve

#: Default number of loads of a path.
DEFAULT_LOADS = 20
#: How alpha_bem is measured (``bem.contact_area``); part of a stored result's request, so
#: results measured otherwise (the plain count of earlier versions) are re-solved.
AREA_ESTIMATE = "subpixel-p2"


@dataclass(frozen=True)
class ValidationResult:
    """BEM against model for one design, at K loads on an M x M grid.

    p_star: (K,) mean pressures P* = P / E*, ascending. alpha_bem, alpha_model: (K,);
    alpha_bem_pixels: (K,) the BEM's plain count of grid points in contact.
    p_max: (K,) largest local p / E*. asperity_alpha_bem / _model: (K, N) contact area of each
    asperity / A_nom (model one None if the model does not resolve asperities). residual,
    seconds: (K,) solver error and wall time per load. pressure: (M, M) p / E* at the
    largest load. heights: the cell's HeightMap. model: the dense model curve.
    """

    name: str
    design: Design
    grid: int
    physics: str
    tolerance: float
    max_iter: int
    p_star: np.ndarray
    alpha_bem: np.ndarray
    alpha_model: np.ndarray
    alpha_bem_pixels: np.ndarray
    p_max: np.ndarray
    asperity_alpha_bem: np.ndarray
    asperity_alpha_model: np.ndarray | None
    residual: np.ndarray
    seconds: np.ndarray
    pressure: np.ndarray
    heights: HeightMap
    model: ModelCurve

    @property
    def rel_err(self) -> np.ndarray:
        """(K,) alpha_bem / alpha_model - 1."""
        return self.alpha_bem / self.alpha_model - 1.0

    @property
    def upper_half(self) -> slice:
        """The upper half of the loads (indices K // 2 .. K - 1)."""
        return slice(len(self.p_star) // 2, None)

    @property
    def max_rel_err_upper(self) -> float:
        """Largest |rel_err| over the upper half of the loads."""
        return float(np.abs(self.rel_err[self.upper_half]).max())

    @property
    def max_rel_err(self) -> float:
        """Largest |rel_err| over all loads."""
        return float(np.abs(self.rel_err).max())

    @property
    def max_rel_err_upper_pixels(self) -> float:
        """``max_rel_err_upper`` with the BEM's plain count of grid points in contact."""
        return float(np.abs(self.alpha_bem_pixels / self.alpha_model - 1.0)[self.upper_half].max())

    def target_error(self, alpha: np.ndarray) -> float | None:
        """Relative curve error of alpha (K,), at this result's loads, against the design's
        target, or None.

        ||alpha - alpha_target||_2 / ||alpha_target||_2 over the loads within the target's
        pressure range (the target interpolated there). None without a target or with no
        load inside its range.
        """
        target = design_target(self.design)
        if target is None:
            return None
        p_t, a_t = target
        inside = (self.p_star >= p_t[0]) & (self.p_star <= p_t[-1] * (1 + 1e-9))
        if not inside.any():
            return None
        ref = np.interp(self.p_star[inside], p_t, a_t)
        norm = float(np.linalg.norm(ref))
        if norm == 0.0:
            return None
        return float(np.linalg.norm(alpha[inside] - ref)) / norm

    def target_errors(self) -> tuple[float, float] | None:
        """``target_error`` of BEM and model: (BEM, model), or None.

        The BEM figure is what the manufactured surface would show; the model one is the
        design's own claim, at the same loads.
        """
        bem = self.target_error(self.alpha_bem)
        if bem is None:
            return None
        return bem, self.target_error(self.alpha_model)  # type: ignore[return-value]

    def summary(self) -> dict[str, Any]:
        """JSON-ready scalars (with the target errors if the design carries a target)."""
        errors = self.target_errors()
        extra = (
            {}
            if errors is None
            else {"target_error_bem": errors[0], "target_error_model": errors[1]}
        )
        return {
            "name": self.name,
            "loads": len(self.p_star),
            "grid": self.grid,
            "physics": self.physics,
            "p_star_max": float(self.p_star[-1]),
            "max_rel_err_upper_half": self.max_rel_err_upper,
            "max_rel_err": self.max_rel_err,
            "max_rel_err_upper_half_pixels": self.max_rel_err_upper_pixels,
            "max_local_pressure": float(self.p_max.max()),
            "max_residual": float(self.residual.max()),
            "bem_seconds": float(self.seconds.sum()),
            **extra,
        }


# --- inputs ------------------------------------------------------------------------------


def resolve_loads(loads: int | Sequence[float] | np.ndarray, p_star_max: float) -> np.ndarray:
    """The load path: K = ``loads`` uniform pressures P*_max i / K (i = 1..K), or the given
    P* values sorted. Every load must lie in (0, P*_max], P*_max reached at Delta_max."""
    if isinstance(loads, int | np.integer) and not isinstance(loads, bool):
        if loads <= 0:
            raise MetainterfaceError(f"loads must be a whole number > 0, got {loads}")
        return p_star_max * np.arange(1, int(loads) + 1) / int(loads)
    try:
        values = np.sort(np.asarray(loads, dtype=np.float64).ravel())
    except (TypeError, ValueError):
        raise MetainterfaceError("loads must be a count K or a list of pressures P*") from None
    if values.size == 0 or not np.isfinite(values).all():
        raise MetainterfaceError("loads must be a non-empty list of finite pressures P*")
    if values[0] <= 0:
        raise MetainterfaceError(
            f"loads: P* = {values[0]:g} is not > 0; allowed range (0, {p_star_max:.6g}]"
        )
    if values[-1] > p_star_max * (1 + 1e-12):
        raise MetainterfaceError(
            f"loads: P* = {values[-1]:.6g} is beyond what the design reaches at Delta_max "
            f"(P*_max = {p_star_max:.6g}); allowed range (0, {p_star_max:.6g}]"
        )
    return np.minimum(values, p_star_max)


def design_target(design: Design) -> tuple[np.ndarray, np.ndarray] | None:
    """The design file's optional "target": {"p_star": [...], "alpha": [...]} as arrays."""
    target = design.extras.get("target")
    if target is None:
        return None
    if not (isinstance(target, dict) and "p_star" in target and "alpha" in target):
        raise MetainterfaceError('target must be an object {"p_star": [...], "alpha": [...]}')
    try:
        p = np.asarray(target["p_star"], dtype=np.float64)
        a = np.asarray(target["alpha"], dtype=np.float64)
    except (TypeError, ValueError):
        raise MetainterfaceError(
            "target.p_star and target.alpha must be lists of numbers"
        ) from None
    if p.ndim != 1 or p.shape != a.shape or p.size < 2:
        raise MetainterfaceError(
            "target.p_star and target.alpha must be lists of one length (>= 2 points)"
        )
    return p, a


@dataclass(frozen=True)
class ValidationPlan:
    """A checked validation case, ready to solve: ``plan_validation(...).solve(jobs)``.

    Light on purpose (no grids, no dense curves), so a sweep can plan thousands of designs.
    loads: (K,) the P* of the path, ascending.
    """

    name: str
    design: Design
    grid: int
    physics: str
    tolerance: float
    max_iter: int
    loads: np.ndarray

    def model(self) -> ModelCurve:
        """The forward model's dense curve (``models.model_curve``)."""
        return model_curve(self.design, self.physics)

    def height_map(self) -> HeightMap:
        """The cell's M x M height map."""
        return height_map(self.design, self.grid)

    def task(self, heights: HeightMap | None = None) -> dict[str, Any]:
        """Keyword arguments of ``bem.solve_path`` / ``bem.solve_loads`` for this case."""
        hm = self.height_map() if heights is None else heights
        return dict(
            heights=hm.heights,
            cell_side=hm.cell_side,
            loads=self.loads,
            owner=hm.owner,
            n_asperities=self.design.n_asperities,
            tolerance=self.tolerance,
            max_iter=self.max_iter,
        )

    def request(self) -> dict[str, Any]:
        """What a stored result must match to be reused (see ``validate_many``)."""
        return _request(
            self.design, self.grid, self.loads, self.physics, self.tolerance, self.max_iter
        )

    def solve(
        self, jobs: int = 1, progress: Callable[[int], Any] | None = None
    ) -> ValidationResult:
        """Run the BEM load path on ``jobs`` processes; progress(n) as loads finish."""
        jobs = _check_jobs(jobs)
        heights, curve = self.height_map(), self.model()
        # PKR needs more iterations as contacts grow, roughly alpha^(1/8) (measured on 384^2
        # paths: 61 -> 82 iterations). Balanced chunks keep every process busy to the end.
        weights = np.maximum(curve.at(self.loads)[0], 1e-12) ** 0.125
        path = solve_loads(**self.task(heights), jobs=jobs, weights=weights, progress=progress)
        return self.result(path, heights=heights, curve=curve)

    def result(
        self,
        path: LoadPath,
        *,
        heights: HeightMap | None = None,
        curve: ModelCurve | None = None,
    ) -> ValidationResult:
        """Assemble the result of a solved load path (model evaluated at the same P*)."""
        curve = self.model() if curve is None else curve
        alpha_model, per_model = curve.at(self.loads)
        return ValidationResult(
            name=self.name,
            design=self.design,
            grid=self.grid,
            physics=self.physics,
            tolerance=self.tolerance,
            max_iter=self.max_iter,
            p_star=self.loads,
            alpha_bem=path.alpha,
            alpha_model=alpha_model,
            alpha_bem_pixels=path.alpha_pixels,
            p_max=path.p_max,
            asperity_alpha_bem=path.asperity_alpha,
            asperity_alpha_model=per_model,
            residual=path.residual,
            seconds=path.seconds,
            pressure=path.pressure,
            heights=self.height_map() if heights is None else heights,
            model=curve,
        )


def plan_validation(
    design: Design,
    grid: int | None = None,
    loads: int | Sequence[float] | np.ndarray = DEFAULT_LOADS,
    *,
    name: str = "design",
    physics: str = "independent",
    tolerance: float = TOLERANCE,
    max_iter: int = MAX_ITER,
) -> ValidationPlan:
    """Check every input and fix the load path; the BEM solve is ``.solve(jobs)``.

    Arguments as in ``validate_design``. Raises MetainterfaceError on bad input.
    """
    if isinstance(max_iter, bool) or not (isinstance(max_iter, int | np.integer) and max_iter >= 1):
        raise MetainterfaceError(f"max_iter must be a whole number >= 1, got {max_iter!r}")
    if not (np.isfinite(tolerance) and tolerance > 0):
        raise MetainterfaceError(f"tolerance must be a number > 0, got {tolerance!r}")
    grid = default_grid(design.settings) if grid is None else check_grid(grid, design.settings)
    design_target(design)  # a malformed target fails now, not after the solve
    p_top = model_curve(design, physics).p_star_max
    return ValidationPlan(
        name=name,
        design=design,
        grid=grid,
        physics=physics,
        tolerance=float(tolerance),
        max_iter=int(max_iter),
        loads=resolve_loads(loads, p_top),
    )


def _check_jobs(jobs: int) -> int:
    if isinstance(jobs, bool) or not isinstance(jobs, int | np.integer) or jobs < 1:
        raise MetainterfaceError(f"jobs must be a whole number >= 1, got {jobs!r}")
    return int(jobs)


# --- one design --------------------------------------------------------------------------


def validate_design(
    design: Design,
    grid: int | None = None,
    loads: int | Sequence[float] | np.ndarray = DEFAULT_LOADS,
    jobs: int = 1,
    *,
    physics: str = "independent",
    tolerance: float = TOLERANCE,
    max_iter: int = MAX_ITER,
    name: str = "design",
    progress: Callable[[int], Any] | None = None,
) -> ValidationResult:
    """BEM (Tamaas) against the forward model ``physics`` for one design.

    grid: M points per side (default 256 n), a multiple of n. loads: K uniform pressures up
    to P*_max (reached at Delta_max), or explicit P* values in (0, P*_max]. jobs: processes;
    the load path is split into ``jobs`` contiguous warm-started chunks. progress(n) is
    called as loads finish. Raises MetainterfaceError on bad input or non-convergence.
    """
    require_tamaas()
    jobs = _check_jobs(jobs)
    prep = plan_validation(
        design,
        name=name,
        grid=grid,
        loads=loads,
        physics=physics,
        tolerance=tolerance,
        max_iter=max_iter,
    )
    return prep.solve(jobs, progress)


# --- output ------------------------------------------------------------------------------


def result_settings(result: ValidationResult, **extra: Any) -> dict[str, Any]:
    """The settings recorded with a result's files."""
    return {
        "design": design_to_dict(result.design),
        "grid": result.grid,
        "loads": [float(p) for p in result.p_star],
        "physics": result.physics,
        "tolerance": result.tolerance,
        "max_iter": result.max_iter,
        "solver": "tamaas PolonskyKeerRey, basic_2d, E* = 1",
        **extra,
    }


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
        from metainterface.plots import plot_validation, save_figure

        fig = plot_validation(result, target=design_target(result.design), title=result.name)
        save_figure(fig, out / "validation.png", **settings)
    record = {
        "request": _request(
            result.design,
            result.grid,
            result.p_star,
            result.physics,
            result.tolerance,
            result.max_iter,
        ),
        "summary": result.summary(),
        "residual": [float(r) for r in result.residual],
        "seconds": [float(s) for s in result.seconds],
        "provenance": provenance(**settings),
    }
    write_text(out / "result.json", json.dumps(record, indent=2) + "\n")
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
            out.append((Path(item).stem, load_design(item)))
    names = [n for n, _ in out]
    dup = sorted({n for n in names if names.count(n) > 1})
    if dup:
        raise MetainterfaceError(f"design names must be unique, repeated: {', '.join(dup)}")
    return out


def _request(
    design: Design, grid: int, loads: np.ndarray, physics: str, tolerance: float, max_iter: int
) -> dict[str, Any]:
    """What a stored result must match to be reused on resume (JSON-normalised)."""
    core = {k: v for k, v in design_to_dict(design).items() if k != "provenance"}
    request = {
        "design": core,
        "grid": int(grid),
        "loads": [float(p) for p in loads],
        "physics": physics,
        "tolerance": float(tolerance),
        "max_iter": int(max_iter),
        "area": AREA_ESTIMATE,
    }
    return json.loads(json.dumps(request, default=str))


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
    physics: str = "independent",
    tolerance: float = TOLERANCE,
    max_iter: int = MAX_ITER,
    figures: bool = False,
    progress: bool = True,
) -> dict[str, dict[str, Any]]:
    """Validate many designs (a folder of design files, a list of files or Designs).

    Each design's results go to ``out_dir/<name>/`` (see ``write_result``) as soon as it is
    done, one design per process with ``jobs > 1``. A design whose result.json records the
    same request (design, grid, loads, physics, solver settings) is skipped, so an
    interrupted sweep resumes where it stopped. A design that fails (e.g. no convergence)
    gets ``error.txt`` and the sweep goes on. ``out_dir/summary.json`` lists every design.
    Returns {name: summary} (summary has an "error" key for failed designs).
    """
    require_tamaas()
    jobs = _check_jobs(jobs)
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
                physics=physics,
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
            json.dumps(
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
