"""The public API: what ``import metainterface as mi`` offers (re-exported there)."""

from metainterface.api.functions import compare, curve, design, export, physical, pressure_check
from metainterface.api.results import Curve, DesignResult
from metainterface.api.tolerance import PrinterSizing, ToleranceResult, min_radius, tolerance
from metainterface.api.training import evaluate_surrogate, generate_dataset, train_surrogate
from metainterface.api.validation_files import validate, validate_many, write_result
from metainterface.api.view import view

__all__ = [
    "Curve",
    "DesignResult",
    "PrinterSizing",
    "ToleranceResult",
    "compare",
    "curve",
    "design",
    "evaluate_surrogate",
    "export",
    "generate_dataset",
    "min_radius",
    "physical",
    "pressure_check",
    "tolerance",
    "train_surrogate",
    "validate",
    "validate_many",
    "view",
    "write_result",
]
