"""A made part: its scan read, registered to its design, its friction law predicted and the
next print corrected (issue 37).

Rooms, one concern each: ``scan`` (reading; SurfaceTopography, the ``measure`` extra),
``surface`` (the fitted family's surface), ``lattice`` (where the lattice lies), ``fit``
(the least-squares fits), ``register`` (the steps together), ``predict`` (BEM and model
of the made part), ``compensate`` (the next print), ``result`` (what is returned and
written), ``run`` (``mi.measure``).
"""

from metainterface.measure.compensate import Compensation, PrintMap, compensate, fit_map
from metainterface.measure.lattice import Lattice
from metainterface.measure.predict import MeasuredCell, Prediction, predict
from metainterface.measure.register import Registration, register
from metainterface.measure.result import Friction, MeasureResult
from metainterface.measure.run import measure
from metainterface.measure.scan import Scan, as_scan, from_array, read_scan

__all__ = [
    "Compensation",
    "Friction",
    "Lattice",
    "MeasureResult",
    "MeasuredCell",
    "Prediction",
    "PrintMap",
    "Registration",
    "Scan",
    "as_scan",
    "compensate",
    "fit_map",
    "from_array",
    "measure",
    "predict",
    "read_scan",
    "register",
]
