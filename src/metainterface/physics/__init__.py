"""The forward model: pure, batched torch functions (no I/O)."""

from metainterface.physics.cell import CellSettings, Design
from metainterface.physics.curves import (
    Curve,
    Sweep,
    alpha_at,
    anchor,
    curve,
    curves_numpy,
    delta_grid,
    design_sweep,
    features_from_normalised,
    interp,
    sweep,
    to_grid,
)
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
    "CellSettings",
    "Curve",
    "Design",
    "Sweep",
    "alpha_at",
    "anchor",
    "area",
    "contact_radius",
    "curve",
    "curves_numpy",
    "delta_grid",
    "design_sweep",
    "engagement",
    "features_from_normalised",
    "force",
    "indentation",
    "interp",
    "kappa",
    "log_kappa",
    "log_kc",
    "shape_constant",
    "sweep",
    "to_grid",
]
