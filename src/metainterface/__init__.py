"""metainterface: inverse design of tribological metainterfaces.

A unit cell holds N axisymmetric power-law asperities (shape exponent gamma_i, height offset
h_i); summed Sneddon closed forms give the contact-area fraction alpha and the dimensionless
pressure P* = P / E*. The package finds (gamma, h) whose alpha(P*) follows a target curve,
and so whose static friction (F_f = tau A_real) follows a chosen law.

Start here::

    import metainterface as mi
    t = mi.Target.builtin("bilinear")        # or mi.Target(p_star=..., alpha=...),
                                             # mi.Target.from_csv, mi.Target.from_friction
    r = mi.design(t)                         # DesignResult: .design, .error, .plot()
    c = mi.curve(r.design, model="interacting")   # Curve: numpy p_star, alpha, stiffness
    v = mi.validate(r.design, grid=96, loads=4)   # BEM check (Tamaas, the [bem] extra)
    mi.export(r.design, "patch.stl", radius="0.5mm", tiles=(2, 2))

Targets and designs
    Target, Design, CellSettings
Designing
    design, compare, DesignResult, pressure_check, physical
Curves and forward models
    curve, Curve, ForwardModel, Independent, Interacting, MODELS, get_model, register_model
Checking and making
    validate, validate_many (sweeps on local processes, a Dask cluster or any
    concurrent.futures.Executor; fields=True keeps the BEM fields), ValidationResult,
    write_result, export
Looking at a design
    view (an interactive, self-contained HTML page; the [view] extra), DesignResult.figure
Manufacturing errors
    tolerance, ToleranceResult (the band of alpha(P*) and the error under height, shape and
    scale errors), min_radius, PrinterSizing (the smallest R for a printer's height error);
    design(..., robust=True, sigma_h=..., sigma_gamma=...) designs for such errors,
    design(..., z_step=...) and export(..., z_step=...) put heights on a printer's layers
Your own design space
    generate_dataset, train_surrogate, TrainConfig, evaluate_surrogate
Process settings
    tune_allocator (keep freed tensor memory in the heap; the CLI calls it)

numpy arrays and lists go in, numpy comes out; the differentiable torch engine is in
``metainterface.physics`` (batched (B, N) tensors). Bad input raises MetainterfaceError
with one line naming the argument and the allowed range.
"""

from importlib.metadata import PackageNotFoundError, version

from metainterface.api import (
    Curve,
    DesignResult,
    PrinterSizing,
    ToleranceResult,
    compare,
    curve,
    design,
    evaluate_surrogate,
    export,
    generate_dataset,
    min_radius,
    physical,
    pressure_check,
    tolerance,
    train_surrogate,
    validate,
    validate_many,
    view,
    write_result,
)
from metainterface.errors import MetainterfaceError
from metainterface.inverse.targets import Target
from metainterface.physics.cell import CellSettings, Design
from metainterface.physics.models import (
    MODELS,
    ForwardModel,
    Independent,
    Interacting,
    get_model,
    register_model,
)
from metainterface.runtime import tune_allocator
from metainterface.surrogate.train import TrainConfig
from metainterface.validation.validate import ValidationResult

try:
    #: The installed package's version (PEP 440); "0+unknown" in an uninstalled source tree.
    __version__ = version("metainterface")
except PackageNotFoundError:  # running from a source tree that was not installed
    __version__ = "0+unknown"

__all__ = [
    "MODELS",
    "CellSettings",
    "Curve",
    "Design",
    "DesignResult",
    "ForwardModel",
    "Independent",
    "Interacting",
    "MetainterfaceError",
    "PrinterSizing",
    "Target",
    "ToleranceResult",
    "TrainConfig",
    "ValidationResult",
    "__version__",
    "compare",
    "curve",
    "design",
    "evaluate_surrogate",
    "export",
    "generate_dataset",
    "get_model",
    "min_radius",
    "physical",
    "pressure_check",
    "register_model",
    "tolerance",
    "train_surrogate",
    "tune_allocator",
    "validate",
    "validate_many",
    "view",
    "write_result",
]
