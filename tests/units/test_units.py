"""Quantities with units -> SI floats; one-line errors naming the option."""

import pytest

from metainterface.errors import MetainterfaceError
from metainterface.units.quantities import (
    parse_area,
    parse_force,
    parse_length,
    parse_pressure,
    parse_pressure_limit,
    parse_quantity,
)


@pytest.mark.parametrize(
    ("text", "parse", "si"),
    [
        ("0.25MPa", parse_pressure, 0.25e6),
        ("2 MPa", parse_pressure, 2e6),
        ("2e6", parse_pressure, 2e6),  # a plain number is SI
        ("0.5mm", parse_length, 0.5e-3),
        ("500 um", parse_length, 0.5e-3),
        ("1e-3", parse_length, 1e-3),
        ("4cm2", parse_area, 4e-4),
        ("4 cm^2", parse_area, 4e-4),
        ("4 cm**2", parse_area, 4e-4),
        ("10 N", parse_force, 10.0),
        ("1 kN", parse_force, 1e3),
    ],
)
def test_units_parse_to_si(text, parse, si):
    assert parse(text) == pytest.approx(si, rel=1e-12)


def test_numbers_pass_through_as_si():
    assert parse_quantity(2.5, "pressure", option="--modulus") == 2.5


@pytest.mark.parametrize(
    ("text", "dimension", "fragment"),
    [
        ("0.5mm", "pressure", "expects a pressure"),  # a length for a stress
        ("2MPa", "length", "not that of a length"),
        ("4cm3", "area", "expects an area"),
        ("abc", "length", "cannot read"),
        ("2 m/", "length", "cannot read"),
        ("", "length", "empty"),
        ("0 mm", "length", "> 0"),
        ("-2 MPa", "pressure", "> 0"),
        ("nan", "length", "finite"),
    ],
)
def test_bad_quantities_name_the_option(text, dimension, fragment):
    with pytest.raises(MetainterfaceError, match="--opt") as err:
        parse_quantity(text, dimension, option="--opt")
    assert fragment in str(err.value)
    assert "\n" not in str(err.value)


def test_pressure_limit_as_ratio_or_stress():
    assert parse_pressure_limit("0.05") == 0.05
    assert parse_pressure_limit("50MPa", e_star=1e9) == pytest.approx(0.05)
    with pytest.raises(MetainterfaceError, match="--modulus"):
        parse_pressure_limit("50MPa")
    with pytest.raises(MetainterfaceError, match=r"p/E\* must be in \(0, 1\]"):
        parse_pressure_limit("5e7")
    with pytest.raises(MetainterfaceError, match="expects a pressure"):
        parse_pressure_limit("5mm", e_star=1e9)
