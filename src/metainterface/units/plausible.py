"""Unit slips: a modulus, shear strength or radius that parses but is almost surely given in
the wrong unit (``--modulus 2.4`` is read as 2.4 Pa; ``--radius 0.5`` as 0.5 m).

Such a value is still used (an unusual material or size may be meant): one
:class:`~metainterface.errors.UnitSlipWarning` per slip names the value and what was
probably meant, attributed to the user's own line (the first frame outside the package).
"""

from __future__ import annotations

import sys
import warnings
from collections.abc import Callable

from metainterface.errors import UnitSlipWarning

#: E* [Pa] outside this range is a unit slip (softest gels ~1 kPa, diamond ~1 TPa).
MODULUS_RANGE = (1e3, 1e12)
#: A radius R [m] above this is a unit slip (an asperity is not larger than a hand).
RADIUS_MAX = 0.1
#: A work of adhesion w [J/m^2] outside this range is a unit slip (issue 52): van der Waals
#: contacts of soft solids give 20-100 mJ/m^2, the strongest tapes about 1 J/m^2; a plain
#: number is read as J/m^2, so '--work-of-adhesion 50' (meant: mJ/m^2) is 50 J/m^2.
WORK_RANGE = (1e-4, 1.0)
#: A modulus a slipped one is scaled towards (1000-fold steps): an elastomer's E*.
_TYPICAL_MODULUS = 1e5

_PREFIXES = ((1e12, "T"), (1e9, "G"), (1e6, "M"), (1e3, "k"), (1.0, ""), (1e-3, "m"))
_PREFIXES += ((1e-6, "u"), (1e-9, "n"), (1e-12, "p"))


def _si(value: float, unit: str, *, space: bool = False) -> str:
    """``value`` [unit] with the SI prefix that leaves 1 <= mantissa < 1000: '2.4MPa'."""
    factor, prefix = next(((f, p) for f, p in _PREFIXES if value >= f), _PREFIXES[-1])
    return f"{value / factor:.4g}{' ' if space else ''}{prefix}{unit}"


def _shown(value: float, unit: str) -> str:
    """The value as it was read: in the SI unit itself where that reads plainly."""
    return f"{value:g} {unit}" if 0.01 <= value < 1000 else _si(value, unit, space=True)


def _meant(value: float, factor: float, done: Callable[[float], bool]) -> float:
    """``value`` times ``factor`` (1e3 or 1e-3: one SI prefix) until ``done``: what a slipped
    value probably meant. At most 12 prefixes, so a zero or an infinity cannot loop."""
    for _ in range(12):
        if done(value):
            break
        value *= factor
    return value


def unit_slips(
    *,
    modulus: float | None = None,
    shear_strength: float | None = None,
    radius: float | None = None,
    work_of_adhesion: float | None = None,
) -> list[str]:
    """One line per implausible value (SI: modulus E* and shear strength tau in Pa, radius R
    in m, work of adhesion w in J/m^2 (0: none); None: not given), each with what was
    probably meant, e.g.
    ``'modulus 2.4 Pa is below 1 kPa: a unit slip? (2.4MPa)'``."""
    out = []
    low, high = MODULUS_RANGE
    modulus_ok = True
    if modulus is not None and modulus < low:
        meant = _meant(modulus, 1e3, lambda v: v >= _TYPICAL_MODULUS)
        out.append(
            f"modulus {_shown(modulus, 'Pa')} is below 1 kPa: a unit slip? ({_si(meant, 'Pa')})"
        )
        modulus_ok = False
    elif modulus is not None and modulus > high:
        meant = _meant(modulus, 1e-3, lambda v: v <= high)
        out.append(
            f"modulus {_shown(modulus, 'Pa')} is above 1 TPa: a unit slip? ({_si(meant, 'Pa')})"
        )
        modulus_ok = False
    too_strong = modulus is not None and shear_strength is not None and shear_strength > modulus
    if modulus_ok and too_strong:
        meant = _meant(shear_strength, 1e-3, lambda v: v <= modulus)
        out.append(
            f"shear strength {_shown(shear_strength, 'Pa')} is above the modulus "
            f"{_shown(modulus, 'Pa')}: a unit slip? ({_si(meant, 'Pa')})"
        )
    if radius is not None and radius > RADIUS_MAX:
        meant = _meant(radius, 1e-3, lambda v: v <= RADIUS_MAX)
        out.append(
            f"radius {_shown(radius, 'm')} is above 10 cm: a unit slip? ({meant * 1e3:.4g}mm)"
        )
    w_low, w_high = WORK_RANGE
    if work_of_adhesion is not None and work_of_adhesion > w_high:
        meant = _meant(work_of_adhesion, 1e-3, lambda v: v <= w_high)
        out.append(
            f"work of adhesion {work_of_adhesion:.4g} J/m^2 is above 1 J/m^2 (a number "
            f"without a unit is J/m^2): a unit slip? ({meant * 1e3:.4g}mJ/m2)"
        )
    elif work_of_adhesion is not None and 0 < work_of_adhesion < w_low:
        meant = _meant(work_of_adhesion, 1e3, lambda v: v >= w_low)
        out.append(
            f"work of adhesion {work_of_adhesion * 1e3:.4g} mJ/m^2 is below 0.1 mJ/m^2: a unit "
            f"slip? ({meant * 1e3:.4g}mJ/m2)"
        )
    return out


def _user_level() -> int:
    """The ``stacklevel`` of the first frame outside the package, seen from the caller."""
    frame = sys._getframe(1)
    level = 1
    while frame is not None:
        name = frame.f_globals.get("__name__", "")
        if not (name.startswith("metainterface.") or name in ("metainterface", "contextlib")):
            break
        frame = frame.f_back
        level += 1
    return level


def warn_unit_slips(
    *,
    modulus: float | None = None,
    shear_strength: float | None = None,
    radius: float | None = None,
    work_of_adhesion: float | None = None,
) -> None:
    """Warn (:class:`UnitSlipWarning`, one per slip) about values :func:`unit_slips` finds
    implausible, at the user's call. SI values as :func:`unit_slips`."""
    for message in unit_slips(
        modulus=modulus,
        shear_strength=shear_strength,
        radius=radius,
        work_of_adhesion=work_of_adhesion,
    ):
        warnings.warn(message, UnitSlipWarning, stacklevel=_user_level())
