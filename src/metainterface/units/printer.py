"""A printer's lengths in units of R: its layer height, and errors given as lengths."""

from __future__ import annotations

import contextlib
from typing import Any

from metainterface import _checks
from metainterface.errors import MetainterfaceError
from metainterface.units.quantities import parse_quantity


def length_in_r(value: Any, radius_m: float | None, *, option: str, radius_option: str) -> float:
    """A length >= 0 in units of R: a plain number is already in units of R; a quantity with
    a unit ('1um') is divided by the radius, which it then needs."""
    if isinstance(value, str):
        with contextlib.suppress(ValueError):  # a plain number: units of R
            value = float(value)
    if isinstance(value, str):
        si = parse_quantity(value, "length", option=option, positive=False)
        if si < 0:
            raise MetainterfaceError(f"{option} must be >= 0, got {value!r}")
        if radius_m is None:
            raise MetainterfaceError(
                f"{option} {value!r} is a length: give {radius_option} (R) too, or {option} "
                "as a plain number in units of R"
            )
        return si / radius_m
    return _checks.number(option, value, low=0.0)


def layer_step(
    value: Any,
    radius_m: float | None,
    delta_max: float,
    *,
    option: str = "z_step",
    radius_option: str = "radius",
) -> float:
    """A printer's layer height in units of R, in (0, Delta_max] (read as in
    :func:`length_in_r`); the range is stated in um when R is known."""
    step = length_in_r(value, radius_m, option=option, radius_option=radius_option)
    if not 0 < step <= delta_max:
        if radius_m:
            span, got = f"{delta_max * radius_m * 1e6:.4g} um", f"{step * radius_m * 1e6:.4g} um"
        else:
            span, got = f"{delta_max:g} R", f"{step:g} R"
        raise MetainterfaceError(
            f"{option} must be in (0, Delta_max = {span}], got {got}", argument=option
        )
    return step
