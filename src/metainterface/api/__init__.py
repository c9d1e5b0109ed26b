"""The public API: what ``import metainterface as mi`` offers (re-exported there)."""

from metainterface.api.functions import compare, curve, design, export, physical, pressure_check
from metainterface.api.results import Curve, DesignResult
from metainterface.api.training import evaluate_surrogate, generate_dataset, train_surrogate
from metainterface.api.validation_files import validate, validate_many, write_result
from metainterface.api.view import view

__all__ = [
    "Curve",
    "DesignResult",
    "compare",
    "curve",
    "design",
    "evaluate_surrogate",
    "export",
    "generate_dataset",
    "physical",
    "pressure_check",
    "train_surrogate",
    "validate",
    "validate_many",
    "view",
    "write_result",
]
