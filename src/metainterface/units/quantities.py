"""Physical quantities given on the command line, parsed with pint and returned in SI.

``"0.25MPa"``, ``"2 MPa"``, ``"0.5mm"``, ``"4cm2"``, ``"4 cm^2"``, ``"10 N"``: the unit is read
by pint (a maintained units library: every SI prefix and unit name, no hand-written table);
a plain number is taken as SI. Each quantity has a required dimension; a wrong dimension,
text that does not parse, or a value that is not finite and > 0 is a one-line
:class:`MetainterfaceError` naming the option and what it expects.

Units live only here, at the edge: the core is dimensionless (R = E* = 1).
"""

from __future__ import annotations

import functools
import math
import re
from typing import Any

from metainterface.errors import MetainterfaceError

#: Dimension name -> (pint dimensionality, SI unit written back, an example for messages).
DIMENSIONS: dict[str, tuple[str, str, str]] = {
    "length": ("[length]", "m", "0.5mm"),
    "area": ("[length] ** 2", "m^2", "4cm2"),
    "pressure": ("[mass] / [length] / [time] ** 2", "Pa", "2MPa"),
    "force": ("[mass] * [length] / [time] ** 2", "N", "10N"),
    "work of adhesion": ("[mass] / [time] ** 2", "J/m^2", "50mJ/m2"),
}

# A leading number, then the unit text: "4cm2" -> ("4", "cm2").
_NUMBER_UNIT = re.compile(r"^\s*([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)\s*(.*?)\s*$")
# In the unit text, a unit name directly followed by a power: "cm2" -> "cm**2".
_UNIT_POWER = re.compile(r"([A-Za-zµμΩ_]+)(\d+)")


@functools.lru_cache(maxsize=1)
def _registry() -> Any:
    import pint

    return pint.UnitRegistry()


def _normalise(text: str) -> str:
    """Write '4cm2' as '4 cm**2' (pint reads 'cm^2' and 'cm**2' but not 'cm2')."""
    match = _NUMBER_UNIT.match(text)
    if match is None:
        return text
    number, unit = match.groups()
    unit = _UNIT_POWER.sub(r"\1**\2", unit)
    return f"{number} {unit}".strip()


def parse_quantity(
    value: str | float | int, dimension: str, *, option: str, positive: bool = True
) -> float:
    """The SI value of ``value`` (a string with a unit, or a number in SI).

    dimension: one of ``DIMENSIONS`` ('length', 'area', 'pressure', 'force').
    option: the option or field name used in error messages (e.g. '--modulus').
    positive: require a value > 0 (moduli, radii, areas, forces).
    Returns a float in m, m^2, Pa or N.
    """
    if dimension not in DIMENSIONS:
        raise ValueError(f"unknown dimension {dimension!r}; one of {', '.join(DIMENSIONS)}")
    dims, si_unit, example = DIMENSIONS[dimension]
    article = "an" if dimension[0] in "aeiou" else "a"
    expect = (
        f"{option} expects {article} {dimension} (e.g. {example}; a plain number is in {si_unit})"
    )
    if isinstance(value, bool):
        raise MetainterfaceError(f"{expect}, got {value!r}", argument=option)
    if isinstance(value, int | float):
        si = float(value)
    else:
        text = str(value).strip()
        if not text:
            raise MetainterfaceError(f"{expect}, got an empty value", argument=option)
        if not re.match(r"[-+]?(\d|\.\d|nan|inf)", text, re.IGNORECASE):  # pint: 'mm' = 1 mm
            raise MetainterfaceError(
                f"{expect}; cannot read {text!r} as a quantity: it does not start with a number",
                argument=option,
            )
        ureg = _registry()
        try:
            quantity = ureg.parse_expression(_normalise(text))
        # pint's expression parser raises many unrelated types on malformed text (PintError,
        # SyntaxError, TokenError, AssertionError, IndexError, ZeroDivisionError, ...).
        except Exception:
            raise MetainterfaceError(
                f"{expect}; cannot read {text!r} as a quantity", argument=option
            ) from None
        try:
            if not isinstance(quantity, ureg.Quantity):  # a plain number: SI
                si = float(quantity)
            elif quantity.dimensionless:
                si = float(quantity.to("dimensionless").magnitude)
            elif quantity.check(dims):
                si = float(quantity.to(si_unit.replace("^", "**")).magnitude)
            else:
                raise MetainterfaceError(
                    f"{expect}; {text!r} has dimension {quantity.dimensionality}, "
                    f"not that of {article} {dimension}",
                    argument=option,
                )
        # a unit to a huge power ('0a90': years^90) overflows pint's conversion factor
        except ArithmeticError:  # (not ValueError: MetainterfaceError is one)
            raise MetainterfaceError(
                f"{expect}; {text!r} is out of the floating-point range", argument=option
            ) from None
    if not math.isfinite(si):
        raise MetainterfaceError(f"{option} must be finite, got {value!r}", argument=option)
    if positive and si <= 0:
        raise MetainterfaceError(f"{option} must be > 0, got {value!r}", argument=option)
    return si


def parse_length(value: str | float, *, option: str = "length") -> float:
    """A length > 0 in metres."""
    return parse_quantity(value, "length", option=option)


def parse_area(value: str | float, *, option: str = "area") -> float:
    """An area > 0 in square metres."""
    return parse_quantity(value, "area", option=option)


def parse_pressure(value: str | float, *, option: str = "pressure") -> float:
    """A stress or modulus > 0 in pascals."""
    return parse_quantity(value, "pressure", option=option)


def parse_force(value: str | float, *, option: str = "force") -> float:
    """A force > 0 in newtons."""
    return parse_quantity(value, "force", option=option)


def parse_work_of_adhesion(value: str | float, *, option: str = "work of adhesion") -> float:
    """A work of adhesion >= 0 in J/m^2 ('50mJ/m2', '0.05 N/m'; a plain number is J/m^2)."""
    w = parse_quantity(value, "work of adhesion", option=option, positive=False)
    if w < 0:
        raise MetainterfaceError(f"{option} must be >= 0, got {value!r}", argument=option)
    return w


#: Force units named in messages about a force column's unit (pint reads any other too).
FORCE_UNITS = "N, mN, kN, µN (or uN)"


def force_unit(unit: str | None, *, where: str) -> float:
    """Newtons per ``unit``, a force unit as a CSV header writes it ('mN', 'kN', 'µN', 'uN';
    None or '' is N). where: the file and column, for the one-line error on a unit that
    pint does not know or that is not a force."""
    if unit is None or not unit.strip():
        return 1.0
    text = unit.strip()
    ureg = _registry()
    try:
        quantity = ureg.Quantity(1.0, ureg.parse_units(_UNIT_POWER.sub(r"\1**\2", text)))
    except Exception:  # pint's parser raises many types on malformed text
        raise MetainterfaceError(
            f"{where}: unknown unit {text!r}; a force column takes {FORCE_UNITS}"
        ) from None
    if not quantity.check(DIMENSIONS["force"][0]):
        raise MetainterfaceError(
            f"{where}: {text!r} is not a force unit; a force column takes {FORCE_UNITS}"
        )
    try:
        return float(quantity.to("N").magnitude)
    except ArithmeticError:  # e.g. N (a/s)^90: a factor past float range
        raise MetainterfaceError(
            f"{where}: {text!r} is out of the floating-point range; a force column takes "
            f"{FORCE_UNITS}"
        ) from None


def parse_pressure_limit(
    value: str | float,
    *,
    e_star: float | None = None,
    option: str = "--max-pressure",
    modulus_option: str = "--modulus",
) -> float:
    """A contact-pressure limit as the dimensionless ratio p / E*.

    A plain number is p / E* and must lie in (0, 1]; a stress with a unit ('50MPa') is
    divided by ``e_star`` [Pa], which is then required (the --modulus option).
    """
    text = str(value).strip()
    try:
        ratio = float(text)
    except ValueError:
        ratio = None
    if ratio is not None:
        if not (math.isfinite(ratio) and 0 < ratio <= 1):
            raise MetainterfaceError(
                f"{option} {text} read as p/E* must be in (0, 1]; give a stress with a unit "
                f"(e.g. 50MPa) together with {modulus_option}",
                argument=option,
            )
        return ratio
    stress = parse_pressure(text, option=option)
    if e_star is None:
        raise MetainterfaceError(
            f"{option} {text} is a stress: give {modulus_option} (E*) too, or the limit as p/E*",
            argument=option,
        )
    if not (math.isfinite(e_star) and e_star > 0):
        raise MetainterfaceError(f"{modulus_option} must be > 0, got {e_star}")
    return stress / e_star
