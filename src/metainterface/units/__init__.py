"""Physical units at the edges of the scale-free core.

Quantities parsed with pint (``quantities``), a friction law in newtons turned into an alpha(P*)
target and back (``friction``, Bowden-Tabor; the law's file and its checks in
``law_file``), and the dimensions of a design in SI for a
given asperity radius and modulus (``dimensions``).
"""

from metainterface.units.dimensions import physical_block
from metainterface.units.friction import (
    FrictionLaw,
    FrictionTarget,
    alpha_to_friction,
    friction_target,
    friction_target_from_options,
    friction_to_alpha,
)
from metainterface.units.law_file import read_friction_csv
from metainterface.units.quantities import (
    parse_area,
    parse_force,
    parse_length,
    parse_pressure,
    parse_pressure_limit,
    parse_quantity,
)

__all__ = [
    "FrictionLaw",
    "FrictionTarget",
    "alpha_to_friction",
    "friction_target",
    "friction_target_from_options",
    "friction_to_alpha",
    "parse_area",
    "parse_force",
    "parse_length",
    "parse_pressure",
    "parse_pressure_limit",
    "parse_quantity",
    "physical_block",
    "read_friction_csv",
]
