"""Validation of the forward models against the boundary element method (Tamaas).

Tamaas is imported only when a solve starts (``bem.require_tamaas``), so this package loads,
and gives a clear message, without it.
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
from metainterface.validation.validate import (
    DEFAULT_LOADS,
    ValidationPlan,
    ValidationResult,
    check_jobs,
    design_target,
    plan_validation,
    resolve_loads,
    validate_design,
    validation_request,
)

__all__ = [
    "DEFAULT_LOADS",
    "MAX_ITER",
    "TOLERANCE",
    "HeightMap",
    "LoadPath",
    "ValidationPlan",
    "ValidationResult",
    "available_cpus",
    "cell_height_map",
    "check_grid",
    "check_jobs",
    "default_grid",
    "design_target",
    "height_map",
    "owner_map",
    "plan_validation",
    "require_tamaas",
    "resolve_loads",
    "solve_loads",
    "solve_path",
    "validate_design",
    "validation_request",
]
