"""The forward model: pure, batched torch functions (no I/O)."""

from metainterface._names import DEFAULT_MODEL
from metainterface.physics.cell import CellSettings, Design
from metainterface.physics.curves import (
    Curve,
    Sweep,
    anchor,
    curve,
    curves_numpy,
    delta_grid,
    design_sweep,
    features_from_normalised,
    idle_mask,
    sweep,
    to_grid,
)
from metainterface.physics.metrics import coverage, curve_error, interp
from metainterface.physics.models import ForwardModel, Independent, Interacting, ModelCurve
from metainterface.physics.pressures import alpha_at
from metainterface.physics.registry import MODELS, get_model, models_at, register_model
from metainterface.physics.sneddon import (
    area,
    contact_radius,
    engagement,
    force,
    indentation,
    kappa,
    log_kappa,
    log_kc,
    shape_constant,
)

__all__ = [
    "DEFAULT_MODEL",
    "MODELS",
    "CellSettings",
    "Curve",
    "Design",
    "ForwardModel",
    "Independent",
    "Interacting",
    "ModelCurve",
    "Sweep",
    "alpha_at",
    "anchor",
    "area",
    "contact_radius",
    "coverage",
    "curve",
    "curve_error",
    "curves_numpy",
    "delta_grid",
    "design_sweep",
    "engagement",
    "features_from_normalised",
    "force",
    "get_model",
    "idle_mask",
    "indentation",
    "interp",
    "kappa",
    "log_kappa",
    "log_kc",
    "models_at",
    "register_model",
    "shape_constant",
    "sweep",
    "to_grid",
]
