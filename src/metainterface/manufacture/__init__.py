"""Manufacturing errors of a made design: the tolerance study (the band of alpha(P*) and
the error under height, shape and scale errors) and printer sizing (the smallest R for a
printer's height error)."""

from metainterface.manufacture.sizing import PrinterSizing, min_radius
from metainterface.manufacture.tolerance import ToleranceResult, tolerance

__all__ = ["PrinterSizing", "ToleranceResult", "min_radius", "tolerance"]
