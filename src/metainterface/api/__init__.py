"""The public API gathered in one place (``import metainterface as mi`` offers the same
names, imported lazily). Each name lives in the room of its concern: ``designer`` (design,
compare, curve, export, physical, pressure_check, view, DesignResult, Curve),
``manufacture`` (tolerance, min_radius), ``sweep`` (validate, validate_many, write_result)
and ``surrogate.build`` (generate_dataset, train_surrogate, evaluate_surrogate)."""

from metainterface.designer.curve_result import Curve
from metainterface.designer.given import curve, export, physical, pressure_check
from metainterface.designer.results import DesignResult
from metainterface.designer.run import compare, design
from metainterface.designer.view import view
from metainterface.manufacture.sizing import PrinterSizing, min_radius
from metainterface.manufacture.tolerance import ToleranceResult, tolerance
from metainterface.surrogate.build import evaluate_surrogate, generate_dataset, train_surrogate
from metainterface.sweep.folders import validate, write_result
from metainterface.sweep.many import validate_many

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
