"""Validation of the forward models against the boundary element method.

Two contact solvers (``engines``): our own in torch (the default, ``torch_bem``) and Tamaas
(the ``bem`` extra, the reference). Tamaas is imported only when its engine is asked for
(``bem.require_tamaas``), so this package loads, and gives a clear message, without it.
"""

from metainterface.validation.bem import (
    MAX_ITER,
    TOLERANCE,
    LoadPath,
    available_cpus,
    require_tamaas,
    solve_loads,
    solve_path,
)
from metainterface.validation.heightmap import (
    HeightMap,
    cell_height_map,
    check_grid,
    default_grid,
    height_map,
    owner_map,
)
from metainterface.validation.result import ValidationResult, design_target
from metainterface.validation.solvers import (
    ENGINES,
    TamaasEngine,
    TorchEngine,
    check_engine,
    get_engine,
    torch_threads,
)
from metainterface.validation.validate import (
    DEFAULT_LOADS,
    ValidationPlan,
    check_jobs,
    plan_validation,
    resolve_loads,
    validate_design,
    validation_request,
)

__all__ = [
    "DEFAULT_LOADS",
    "ENGINES",
    "MAX_ITER",
    "TOLERANCE",
    "HeightMap",
    "LoadPath",
    "TamaasEngine",
    "TorchEngine",
    "ValidationPlan",
    "ValidationResult",
    "available_cpus",
    "cell_height_map",
    "check_engine",
    "check_grid",
    "check_jobs",
    "default_grid",
    "design_target",
    "get_engine",
    "height_map",
    "owner_map",
    "plan_validation",
    "require_tamaas",
    "resolve_loads",
    "solve_loads",
    "solve_path",
    "torch_threads",
    "validate_design",
    "validation_request",
]
