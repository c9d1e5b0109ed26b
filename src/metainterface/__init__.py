"""metainterface: inverse design of tribological metainterfaces.

A unit cell holds N axisymmetric power-law asperities (shape exponent gamma_i, height offset
h_i); summed Sneddon closed forms give the contact-area fraction alpha and the dimensionless
pressure P* = P / E*. The package finds (gamma, h) whose alpha(P*) follows a target curve,
and so whose static friction (F_f = tau A_real) follows a chosen law.

Start here::

    import metainterface as mi
    t = mi.Target.builtin("bilinear")        # or mi.Target(p_star=..., alpha=...),
                                             # mi.Target.from_csv, mi.Target.from_friction
    r = mi.design(t)                         # DesignResult: .design, .error, .bem_error, .plot()
    c = mi.curve(r.design, model="interacting")   # Curve: numpy p_star, alpha, stiffness
    v = mi.validate(r.design, grid=96, loads=4)   # BEM check (torch; engine="tamaas": [bem])
    mi.export(r.design, "patch.stl", radius="0.5mm", tiles=(2, 2))

Targets and designs
    Target, Design, CellSettings
Designing
    design, compare, DesignResult, pressure_check, physical, reachability (can a cell
    follow this friction law at this E*, tau and area?), Reachability, UnreachableError,
    UnitSlipWarning (a modulus, shear strength or radius that looks like a unit slip),
    ReachWarning (a target partly out of reach, said before a design starts),
    feasible_scale (which area, E* or tau makes a friction law reachable, FeasibleScale),
    design_scale (a friction law designed with its area, E* or tau chosen too)
Design options
    Effort, Scale, Robust (groups of design's options, built once and reused)
    design(t, effort=Effort(starts=8), scale=Scale(radius="0.5mm", modulus="2MPa"),
    robust=Robust(sigma_h="1um")): the search, the user's scale, the printer's errors
Checked in BEM
    Verify (how design checks, and corrects, each design in BEM), BemCheck (the BEM curve
    and its error to the target: DesignResult.bem)
Curves and forward models
    curve, Curve, ForwardModel, Independent, Interacting, MODELS, get_model, register_model
Checking and making
    validate, validate_many (sweeps on local processes, a Dask cluster or any
    concurrent.futures.Executor; fields=True keeps the BEM fields), ValidationResult,
    write_result, export
Looking at a design
    view (an interactive, self-contained HTML page; the [view] extra), DesignResult.figure
The part as made
    measure, MeasureResult
    (a scan of the made part in, in any orientation, registered to its design, every
    asperity fitted, layer steps and cut tips found; its law predicted by BEM on the
    measured cell, with the BEM's own accuracy; .compensate(): the geometry to print next
    so that the made part meets the target, modelled on the process and checked in BEM;
    .report(): the summary on screen; the [measure] extra reads the scan)
Manufacturing errors
    tolerance, ToleranceResult (the band of alpha(P*) and the error under height, shape and
    scale errors), min_radius, PrinterSizing (the smallest R for a printer's height error);
    design(..., robust=True, sigma_h=..., sigma_gamma=...) designs for such errors,
    design(..., z_step=...) and export(..., z_step=...) put heights on a printer's layers
Your own design space
    generate_dataset, train_surrogate, TrainConfig, evaluate_surrogate
Process settings
    set_threads (torch's CPU threads for metainterface's work; by default one for designs
    and BEM, all for training, and the user's OMP_NUM_THREADS or torch.set_num_threads wins),
    tune_allocator (keep freed tensor memory in the heap; the CLI calls it)

numpy arrays and lists go in, numpy comes out; the differentiable torch engine is in
``metainterface.physics`` (batched (B, N) tensors). Bad input raises MetainterfaceError
with one line naming the argument and the allowed range.
"""

import sys
import types
from importlib.metadata import PackageNotFoundError, version
from typing import TYPE_CHECKING, Any

from metainterface import _threads

# Before anything loads torch: its OpenMP threads should sleep, not spin, while they wait
# (a busy machine made them 10-18x slower; metainterface._threads says why and how).
_threads.prepare_process()

try:
    #: The installed package's version (PEP 440); "0+unknown" in an uninstalled source tree.
    __version__ = version("metainterface")
except PackageNotFoundError:  # running from a source tree that was not installed
    __version__ = "0+unknown"

#: Where each public name lives. ``import metainterface`` imports none of them (so the
#: command line's ``--help`` answers without torch); a name's module is imported on first use
#: (PEP 562), and ``dir(mi)``, ``help(mi)`` and the API reference still list every name.
_HOMES: dict[str, str] = {
    "Curve": "metainterface.designer.curve_result",
    "DesignResult": "metainterface.designer.results",
    "PrinterSizing": "metainterface.manufacture.sizing",
    "ToleranceResult": "metainterface.manufacture.tolerance",
    "compare": "metainterface.designer.run",
    "curve": "metainterface.designer.given",
    "design": "metainterface.designer.run",
    "evaluate_surrogate": "metainterface.surrogate.build",
    "export": "metainterface.designer.given",
    "generate_dataset": "metainterface.surrogate.build",
    "min_radius": "metainterface.manufacture.sizing",
    "physical": "metainterface.designer.given",
    "pressure_check": "metainterface.designer.given",
    "tolerance": "metainterface.manufacture.tolerance",
    "train_surrogate": "metainterface.surrogate.build",
    "validate": "metainterface.sweep.folders",
    "validate_many": "metainterface.sweep.many",
    "view": "metainterface.designer.view",
    "write_result": "metainterface.sweep.folders",
    "design_scale": "metainterface.scaling.choose",
    "Effort": "metainterface.designer.options",
    "Robust": "metainterface.designer.options",
    "Scale": "metainterface.designer.options",
    "feasible_scale": "metainterface.scaling.choose",
    "MetainterfaceError": "metainterface.errors",
    "UnreachableError": "metainterface.errors",
    "UnitSlipWarning": "metainterface.errors",
    "ReachWarning": "metainterface.errors",
    "Reachability": "metainterface.inverse.verdict",
    "reachability": "metainterface.inverse.verdict",
    "Target": "metainterface.inverse.targets",
    "CellSettings": "metainterface.physics.cell",
    "Design": "metainterface.physics.cell",
    "MODELS": "metainterface.physics.registry",
    "ForwardModel": "metainterface.physics.models",
    "Independent": "metainterface.physics.models",
    "Interacting": "metainterface.physics.models",
    "get_model": "metainterface.physics.registry",
    "register_model": "metainterface.physics.registry",
    "tune_allocator": "metainterface.runtime",
    "set_threads": "metainterface._threads",
    "TrainConfig": "metainterface.surrogate.config",
    "ValidationResult": "metainterface.validation.result",
    "FeasibleScale": "metainterface.scaling.search",
    "BemCheck": "metainterface.verify.bemcheck",
    "Verify": "metainterface.verify.check",
    "measure": "metainterface.measure.run",
    "MeasureResult": "metainterface.measure.result",
}

if TYPE_CHECKING:  # what type checkers and IDEs see
    from metainterface._threads import set_threads
    from metainterface.designer.curve_result import Curve
    from metainterface.designer.given import curve, export, physical, pressure_check
    from metainterface.designer.options import Effort, Robust, Scale
    from metainterface.designer.results import DesignResult
    from metainterface.designer.run import compare, design
    from metainterface.designer.view import view
    from metainterface.errors import (
        MetainterfaceError,
        ReachWarning,
        UnitSlipWarning,
        UnreachableError,
    )
    from metainterface.inverse.targets import Target
    from metainterface.inverse.verdict import Reachability, reachability
    from metainterface.manufacture.sizing import PrinterSizing, min_radius
    from metainterface.manufacture.tolerance import ToleranceResult, tolerance
    from metainterface.measure.result import MeasureResult
    from metainterface.measure.run import measure
    from metainterface.physics.cell import CellSettings, Design
    from metainterface.physics.models import ForwardModel, Independent, Interacting
    from metainterface.physics.registry import MODELS, get_model, register_model
    from metainterface.runtime import tune_allocator
    from metainterface.scaling.choose import design_scale, feasible_scale
    from metainterface.scaling.search import FeasibleScale
    from metainterface.surrogate.build import evaluate_surrogate, generate_dataset, train_surrogate
    from metainterface.surrogate.config import TrainConfig
    from metainterface.sweep.folders import validate, write_result
    from metainterface.sweep.many import validate_many
    from metainterface.validation.result import ValidationResult
    from metainterface.verify.bemcheck import BemCheck
    from metainterface.verify.check import Verify


def __getattr__(name: str) -> Any:
    home = _HOMES.get(name)
    if home is None:
        raise AttributeError(f"module 'metainterface' has no attribute {name!r}")
    import importlib

    value = getattr(importlib.import_module(home), name)
    globals()[name] = value  # later look-ups skip this function
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(__all__))


class _Face(types.ModuleType):
    """This package's module type: a public name is never replaced by a subpackage.

    The import system sets a subpackage as an attribute of its parent when it first loads it;
    ``physical`` is both a subpackage and a public function, and with lazy names that load
    may come after the function was looked up. The function stays.
    """

    def __setattr__(self, name: str, value: Any) -> None:
        if name in _HOMES and isinstance(value, types.ModuleType):
            return
        super().__setattr__(name, value)


sys.modules[__name__].__class__ = _Face


__all__ = [
    "MODELS",
    "BemCheck",
    "CellSettings",
    "Curve",
    "Design",
    "DesignResult",
    "Effort",
    "FeasibleScale",
    "ForwardModel",
    "Independent",
    "Interacting",
    "MeasureResult",
    "MetainterfaceError",
    "PrinterSizing",
    "ReachWarning",
    "Reachability",
    "Robust",
    "Scale",
    "Target",
    "ToleranceResult",
    "TrainConfig",
    "UnitSlipWarning",
    "UnreachableError",
    "ValidationResult",
    "Verify",
    "__version__",
    "compare",
    "curve",
    "design",
    "design_scale",
    "evaluate_surrogate",
    "export",
    "feasible_scale",
    "generate_dataset",
    "get_model",
    "measure",
    "min_radius",
    "physical",
    "pressure_check",
    "reachability",
    "register_model",
    "set_threads",
    "tolerance",
    "train_surrogate",
    "tune_allocator",
    "validate",
    "validate_many",
    "view",
    "write_result",
]
