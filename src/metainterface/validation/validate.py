"""Validate a design against BEM: plan the case, solve the load path, compare with a model.

For each design: the height map (``heightmap``), a BEM load path of K ascending mean
pressures (``bem``) and a forward model at the same P* (``ForwardModel.model_curve``,
interpolated on its dense exact Delta sweep). Writing results to disk and sweeps over many
designs are ``metainterface.sweep``'s.
Many designs solved as one torch batch: ``metainterface.validation.batched``.

rel_err = alpha_bem / alpha_model - 1 (signed). Everything is dimensionless (E* = 1).
alpha_bem places the contact edges to sub-pixel accuracy (``bem.contact_area``);
alpha_bem_pixels is the plain count of grid points in contact, a few % high on coarse grids.
"""

from __future__ import annotations

import json
import os
from collections.abc import Callable, Sequence
from concurrent.futures import Executor
from dataclasses import dataclass
from typing import Any

import numpy as np
import torch

from metainterface import _checks
from metainterface._names import DEFAULT_ENGINE
from metainterface.errors import MetainterfaceError
from metainterface.physics.cell import Design
from metainterface.physics.models import ForwardModel, ModelCurve
from metainterface.physics.registry import get_model
from metainterface.physics.sneddon import shape_constant
from metainterface.validation.bem import (
    MAX_ITER,
    TOLERANCE,
    LoadPath,
    solve_loads,
    split_path,
)
from metainterface.validation.executors import BemTask, solve_task, stream
from metainterface.validation.heightmap import HeightMap, check_grid, default_grid, height_map
from metainterface.validation.result import (
    ValidationResult,
    design_target,
)
from metainterface.validation.solvers import check_engine

#: Default number of loads of a path.
DEFAULT_LOADS = 20
#: How alpha_bem is measured (``bem.contact_area``); part of a stored result's request, so
#: results measured otherwise (the plain count of earlier versions) are re-solved.
AREA_ESTIMATE = "subpixel-p2"


# --- inputs ------------------------------------------------------------------------------


def resolve_loads(loads: int | Sequence[float] | np.ndarray, p_star_max: float) -> np.ndarray:
    """The load path: K = ``loads`` uniform pressures P*_max i / K (i = 1..K), or the given
    P* values sorted. Every load must lie in (0, P*_max], P*_max reached at Delta_max."""
    if isinstance(loads, int | np.integer) and not isinstance(loads, bool):
        k = _checks.whole("loads", loads, low=1, high=MAX_LOADS)
        return p_star_max * np.arange(1, k + 1) / k
    try:
        values = np.sort(np.asarray(loads, dtype=np.float64).ravel())
    except (TypeError, ValueError):
        raise MetainterfaceError("loads must be a count K or a list of pressures P*") from None
    if values.size == 0 or not np.isfinite(values).all():
        raise MetainterfaceError("loads must be a non-empty list of finite pressures P*")
    if values.size > MAX_LOADS:
        raise MetainterfaceError(
            f"loads: {values.size} pressures, more than {MAX_LOADS} (each is a BEM solve)",
            argument="loads",
        )
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


@dataclass(frozen=True)
class ValidationPlan:
    """A checked validation case, ready to solve: ``plan_validation(...).solve(jobs)``.

    Light on purpose (no grids, no dense curves), so a sweep can plan thousands of designs.
    loads: (K,) the P* of the path, ascending. engine: the contact solver's name; device:
    where the torch engine runs (resolved where it solves).
    """

    name: str
    design: Design
    grid: int
    model: ForwardModel
    tolerance: float
    max_iter: int
    loads: np.ndarray
    engine: str = DEFAULT_ENGINE
    device: str = "auto"

    def model_curve(self) -> ModelCurve:
        """The forward model's dense curve of the design."""
        return self.model.model_curve(self.design)

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
            engine=self.engine,
            device=self.device,
        )

    def request(self) -> dict[str, Any]:
        """What a stored result must match to be reused (see ``validate_many``)."""
        return validation_request(
            self.design,
            self.grid,
            self.loads,
            self.model,
            self.tolerance,
            self.max_iter,
            engine=self.engine,
        )

    def contact_depths(self, curve: ModelCurve | None = None) -> np.ndarray | None:
        """(K, N) where the model puts each asperity's contact edge at each load, as its
        depth below the tip, c a^gamma [length] (the torch engine's first guess,
        ``bem.solve_path``); None for Tamaas (it starts on its own) or a model that does not
        resolve the asperities."""
        if self.engine != "torch":
            return None
        curve = self.model_curve() if curve is None else curve
        _, per = curve.at(self.loads)
        if per is None:
            return None
        s = self.design.settings
        radius = np.sqrt(np.clip(per, 0.0, None) * s.nominal_area / np.pi)  # a = sqrt(A / pi)
        gamma = np.asarray(self.design.gamma, dtype=np.float64)
        return shape_constant(torch.as_tensor(gamma), s.radius).numpy() * radius**gamma

    def load_weights(self, curve: ModelCurve | None = None) -> np.ndarray:
        """(K,) expected relative cost of each load, to balance a path's chunks."""
        curve = self.model_curve() if curve is None else curve
        # PKR needs more iterations as contacts grow, roughly alpha^(1/8) (measured on 384^2
        # paths: 61 -> 82 iterations). Balanced chunks keep every process busy to the end.
        return np.maximum(curve.at(self.loads)[0], 1e-12) ** 0.125

    def tasks(
        self,
        chunks: int = 1,
        *,
        fields: bool = False,
        curve: ModelCurve | None = None,
        threads: int | None = 1,
    ) -> list[BemTask]:
        """The path as ``chunks`` contiguous warm-started tasks of about equal cost; torch
        runs on ``threads`` threads in the worker (None: as set there)."""
        weights = self.load_weights(curve) if chunks > 1 else None
        parts = split_path(len(self.loads), chunks, weights)
        depths = self.contact_depths(curve)
        return [
            BemTask(
                design=self.design,
                grid=self.grid,
                loads=self.loads[c],
                first_index=int(c[0]),
                total=len(self.loads),
                tolerance=self.tolerance,
                max_iter=self.max_iter,
                fields=fields,
                engine=self.engine,
                device=self.device,
                threads=threads,
                contact_depth=None if depths is None else depths[c[0]],
            )
            for c in parts
        ]

    def solve(
        self,
        jobs: int = 1,
        progress: Callable[[int], Any] | None = None,
        *,
        executor: Executor | None = None,
        fields: bool = False,
    ) -> ValidationResult:
        """Run the BEM load path as ``jobs`` warm-started chunks; progress(n) as loads finish.

        executor: run the chunks there (any ``concurrent.futures.Executor``); default local
        processes. fields: keep every load's pressure and gap fields.
        """
        jobs = check_jobs(jobs)
        heights, curve = self.height_map(), self.model_curve()
        if executor is None and jobs > 1 and self.engine == "torch":
            from metainterface._device import resolve_device

            if resolve_device(self.device).type == "cuda":
                jobs = 1  # one process drives the GPU (a forked child cannot use CUDA)
        if executor is None:
            path = solve_loads(
                **self.task(heights),
                jobs=jobs,
                weights=self.load_weights(curve),
                progress=progress,
                fields=fields,
                contact_depths=self.contact_depths(curve),
            )
            return self.result(path, heights=heights, curve=curve)
        tasks = self.tasks(jobs, fields=fields, curve=curve)
        parts: list[LoadPath | None] = [None] * len(tasks)

        def done(i: int, part: LoadPath) -> None:
            parts[i] = part
            if progress is not None:
                progress(len(tasks[i].loads))

        def fail(i: int, exc: BaseException) -> None:
            raise exc

        stream(solve_task, tasks, executor=executor, on_done=done, on_error=fail)
        path = LoadPath.concat([p for p in parts if p is not None])
        return self.result(path, heights=heights, curve=curve)

    def result(
        self,
        path: LoadPath,
        *,
        heights: HeightMap | None = None,
        curve: ModelCurve | None = None,
    ) -> ValidationResult:
        """Assemble the result of a solved load path (model evaluated at the same P*)."""
        curve = self.model_curve() if curve is None else curve
        alpha_model, per_model = curve.at(self.loads)
        return ValidationResult(
            name=self.name,
            design=self.design,
            grid=self.grid,
            model=self.model,
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
            curve=curve,
            pressures=path.pressures,
            gaps=path.gaps,
            engine=self.engine,
        )


#: Most loads of one path: each is a full BEM solve (seconds to minutes on a fine grid).
MAX_LOADS = 10_000
#: Loosest tolerance of the contact solve accepted: above it a "converged" solve is not a
#: solution (the paper's is 1e-11; 1e-9 gives the same areas).
MAX_TOLERANCE = 1e-6


def plan_validation(
    design: Design,
    grid: int | None = None,
    loads: int | Sequence[float] | np.ndarray = DEFAULT_LOADS,
    *,
    name: str = "design",
    model: str | ForwardModel | None = None,
    tolerance: float = TOLERANCE,
    max_iter: int = MAX_ITER,
    engine: str = DEFAULT_ENGINE,
    device: str = "auto",
) -> ValidationPlan:
    """Check every input and fix the load path; the BEM solve is ``.solve(jobs)``.

    Arguments as in ``validate_design``. Raises MetainterfaceError on bad input (an unknown
    engine, Tamaas missing for engine="tamaas", a device torch does not see).
    """
    solver = check_engine(engine, device)
    if isinstance(max_iter, bool) or not (isinstance(max_iter, int | np.integer) and max_iter >= 1):
        raise MetainterfaceError(f"max_iter must be a whole number >= 1, got {max_iter!r}")
    tolerance = _checks.number("tolerance", tolerance, low=0.0, low_open=True, high=MAX_TOLERANCE)
    grid = default_grid(design.settings) if grid is None else check_grid(grid, design.settings)
    design_target(design)  # a malformed target fails now, not after the solve
    model = get_model(model)
    if model.adhesion:
        # this BEM has no adhesion: against an adhesive model every load would read the
        # adhesion's own effect (tens of per cent at low load) as the model's error
        raise MetainterfaceError(
            f"model {model.label} has adhesion, which this BEM leaves out: one adhesive "
            "design is validated in the adhesive (JKR-limit) BEM by mi.validate (or the "
            "validate command with one design) and checked by design's check; here compare "
            "the adhesionless model, e.g. model='independent'",
            argument="model",
        )
    p_top = model.model_curve(design).p_star_max
    return ValidationPlan(
        name=name,
        design=design,
        grid=grid,
        model=model,
        tolerance=float(tolerance),
        max_iter=int(max_iter),
        loads=resolve_loads(loads, p_top),
        engine=solver.name,
        device=_device_name(device),
    )


def _device_name(device: Any) -> str:
    """The device as text (a plan travels to workers, which resolve it themselves)."""
    return device.strip().lower() if isinstance(device, str) else str(device)


def check_jobs(jobs: int) -> int:
    """Processes: at least 1, at most four per core (more only thrash, and a typo of
    10000 would start 10000 processes)."""
    return _checks.whole("jobs", jobs, low=1, high=4 * (os.cpu_count() or 1))


# --- one design --------------------------------------------------------------------------


def validate_design(
    design: Design,
    grid: int | None = None,
    loads: int | Sequence[float] | np.ndarray = DEFAULT_LOADS,
    jobs: int = 1,
    *,
    model: str | ForwardModel | None = None,
    tolerance: float = TOLERANCE,
    max_iter: int = MAX_ITER,
    name: str = "design",
    progress: Callable[[int], Any] | None = None,
    engine: str = DEFAULT_ENGINE,
    device: str = "auto",
) -> ValidationResult:
    """BEM against the forward ``model`` (default: independent) for one design.

    grid: M points per side (default 256 n), a multiple of n. loads: K uniform pressures up
    to P*_max (reached at Delta_max), or explicit P* values in (0, P*_max]. jobs: processes;
    the load path is split into ``jobs`` contiguous warm-started chunks. progress(n) is
    called as loads finish. engine: "torch" (default; ``device`` "auto", "cpu", "cuda" or
    "cuda:N") or "tamaas" (the ``bem`` extra). Raises MetainterfaceError on bad input or
    non-convergence.
    """
    jobs = check_jobs(jobs)
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
    return prep.solve(jobs, progress)


def validation_request(
    design: Design,
    grid: int,
    loads: np.ndarray,
    model: ForwardModel,
    tolerance: float,
    max_iter: int,
    *,
    engine: str = DEFAULT_ENGINE,
) -> dict[str, Any]:
    """What a stored result must match to be reused on resume (JSON-normalised); the
    engine is part of it, so a resumed sweep never mixes two engines' results."""
    core = {k: v for k, v in design.to_dict().items() if k != "provenance"}
    request = {
        "design": core,
        "grid": int(grid),
        "loads": [float(p) for p in loads],
        "model": model.label,
        "tolerance": float(tolerance),
        "max_iter": int(max_iter),
        "area": AREA_ESTIMATE,
        "engine": engine,
    }
    return json.loads(json.dumps(request, default=str))
