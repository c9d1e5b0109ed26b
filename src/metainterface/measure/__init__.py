"""A made part: its scan read, registered to its design, its friction law predicted and the
next print corrected (issue 37).

Rooms, one concern each: ``scan`` (reading; SurfaceTopography, the ``measure`` extra),
``surface`` (the fitted family's surface), ``lattice`` (where the lattice lies), ``fit``
(the least-squares fits), ``register`` (the steps together).
"""

from metainterface.measure.lattice import Lattice
from metainterface.measure.register import Registration, register
from metainterface.measure.scan import Scan, as_scan, from_array, read_scan

__all__ = ["Lattice", "Registration", "Scan", "as_scan", "from_array", "read_scan", "register"]
