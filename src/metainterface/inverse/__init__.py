"""Inverse design: targets, parameterisations, the batched multi-stage refinement, the pipeline."""

from metainterface.inverse.envelope import (
    reach_violation,
    reachability_warnings,
    reachable_envelope,
)
from metainterface.inverse.losses import TargetGrid, relative_error
from metainterface.inverse.params import FULL, HERTZ, Parameterisation
from metainterface.inverse.pipeline import METHODS, DesignResult, design, predict
from metainterface.inverse.refine import RefineSettings
from metainterface.inverse.targets import (
    BUILTIN_TARGETS,
    Target,
    builtin_target,
    target_features,
    target_from_csv,
)

__all__ = [
    "BUILTIN_TARGETS",
    "FULL",
    "HERTZ",
    "METHODS",
    "DesignResult",
    "Parameterisation",
    "RefineSettings",
    "Target",
    "TargetGrid",
    "builtin_target",
    "design",
    "predict",
    "reach_violation",
    "reachability_warnings",
    "reachable_envelope",
    "relative_error",
    "target_features",
    "target_from_csv",
]
