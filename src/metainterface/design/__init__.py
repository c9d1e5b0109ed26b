"""Inverse design: targets, the batched multi-stage L-BFGS refinement, the pipeline."""

from metainterface.design.pipeline import (
    METHODS,
    DesignResult,
    design,
    predict,
    reachability_warnings,
    reachable_envelope,
)
from metainterface.design.refine import RefineSettings, TargetGrid, relative_error
from metainterface.design.targets import (
    BUILTIN_TARGETS,
    Target,
    builtin_target,
    target_features,
    target_from_csv,
)

__all__ = [
    "BUILTIN_TARGETS",
    "METHODS",
    "DesignResult",
    "RefineSettings",
    "Target",
    "TargetGrid",
    "builtin_target",
    "design",
    "predict",
    "reachability_warnings",
    "reachable_envelope",
    "relative_error",
    "target_features",
    "target_from_csv",
]
