"""A friction law's scale as a design variable: which nominal area, modulus or shear
strength makes the law reachable by the cell (``search``: the envelope test and the search
over one scale factor), and the public calls that answer it in the user's units and design
with the scale chosen (``choose``: :func:`feasible_scale`, :func:`design_scale`).
"""

from metainterface.scaling.choose import design_scale, feasible_scale
from metainterface.scaling.search import FeasibleScale

__all__ = ["FeasibleScale", "design_scale", "feasible_scale"]
