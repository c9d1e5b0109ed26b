"""Validation of the independent-asperity model against the boundary element method.

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
from metainterface.validation.models import (
    MODELS,
    ModelCurve,
    independent_asperities,
    model_curve,
    register_model,
)
from metainterface.validation.validate import (
    DEFAULT_LOADS,
    ValidationPlan,
    ValidationResult,
    design_target,
    plan_validation,
    resolve_loads,
    validate_design,
    validate_many,
    write_result,
)

__all__ = [
    "DEFAULT_LOADS",
    "MAX_ITER",
    "MODELS",
    "TOLERANCE",
    "HeightMap",
    "LoadPath",
    "ModelCurve",
    "ValidationPlan",
    "ValidationResult",
    "available_cpus",
    "cell_height_map",
    "check_grid",
    "default_grid",
    "design_target",
    "height_map",
    "independent_asperities",
    "model_curve",
    "owner_map",
    "plan_validation",
    "register_model",
    "require_tamaas",
    "resolve_loads",
    "solve_loads",
    "solve_path",
    "validate_design",
    "validate_many",
    "write_result",
]
