"""A made part: its scan read, registered to its design, its friction law predicted and the
next print corrected (issues 37, 51).

Rooms, one concern each: ``scan`` (reading; SurfaceTopography, the ``measure`` extra),
``surface`` (the fitted family's surface), ``lattice`` (where the lattice lies), ``orient``
(which way round the part lies: the lattice's 8 symmetries), ``fit`` (the least-squares
fits), ``register`` (the steps together), ``shapes`` (what the family cannot describe:
noise, layers, cut tips, extra or missing material), ``predict`` (BEM and model of the made
part), ``compensate`` (the process and the next print), ``result`` (what is returned and
written), ``run`` (``mi.measure``).
"""

from metainterface.measure.compensate import (
    Compensation,
    PrintMap,
    Process,
    compensate,
    fit_map,
    process_from,
)
from metainterface.measure.lattice import Lattice
from metainterface.measure.orient import Orientation
from metainterface.measure.predict import MeasuredCell, Prediction, predict
from metainterface.measure.register import Registration, register
from metainterface.measure.result import Friction, MeasureResult
from metainterface.measure.run import measure
from metainterface.measure.scan import Scan, as_scan, from_array, read_scan
from metainterface.measure.shapes import Shapes, Terraces

__all__ = [
    "Compensation",
    "Friction",
    "Lattice",
    "MeasureResult",
    "MeasuredCell",
    "Orientation",
    "Prediction",
    "PrintMap",
    "Process",
    "Registration",
    "Scan",
    "Shapes",
    "Terraces",
    "as_scan",
    "compensate",
    "fit_map",
    "from_array",
    "measure",
    "predict",
    "process_from",
    "read_scan",
    "register",
]
