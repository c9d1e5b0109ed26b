"""metainterface: inverse design of tribological metainterfaces.

A unit cell holds N axisymmetric power-law asperities (shape exponent gamma_i, height offset
h_i); summed Sneddon closed forms give the contact-area fraction alpha and the dimensionless
pressure P* = P / E*. The package finds (gamma, h) whose alpha(P*) follows a target curve.
"""

from importlib.metadata import PackageNotFoundError, version

from metainterface.errors import MetainterfaceError
from metainterface.physics import CellSettings, Curve, Design, curve, sweep

try:
    __version__ = version("metainterface")
except PackageNotFoundError:  # running from a source tree that was not installed
    __version__ = "0+unknown"

__all__ = [
    "CellSettings",
    "Curve",
    "Design",
    "MetainterfaceError",
    "__version__",
    "curve",
    "sweep",
]
