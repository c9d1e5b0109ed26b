"""Checks of user-facing values, shared by the Python API and the command line.

Each returns the value normalised (int or float) or raises MetainterfaceError with one line
that names the argument and the allowed range. The CLI reports its options under their
``--option`` names by passing them as ``name``.
"""

from __future__ import annotations

import math
import numbers
from collections.abc import Iterable
from typing import Any

from metainterface.errors import MetainterfaceError


def _range(low: float | None, high: float | None, low_open: bool, high_open: bool) -> str:
    lo = "(" if low_open or low is None else "["
    hi = ")" if high_open or high is None else "]"
    return (
        f"{lo}{'-inf' if low is None else f'{low:g}'}, {'inf' if high is None else f'{high:g}'}{hi}"
    )


def whole(name: str, value: Any, *, low: int | None = None, high: int | None = None) -> int:
    """An integer in [low, high] (bools and non-integral numbers refused)."""
    ok = isinstance(value, numbers.Integral) and not isinstance(value, bool)
    if not ok:
        raise MetainterfaceError(
            f"{name} must be a whole number in {_range(low, high, False, False)}, got {value!r}"
        )
    value = int(value)
    if (low is not None and value < low) or (high is not None and value > high):
        raise MetainterfaceError(
            f"{name} must be a whole number in {_range(low, high, False, False)}, got {value}"
        )
    return value


def number(
    name: str,
    value: Any,
    *,
    low: float | None = None,
    high: float | None = None,
    low_open: bool = False,
    high_open: bool = False,
) -> float:
    """A finite real number in the range given (ends closed unless ``*_open``)."""
    span = _range(low, high, low_open, high_open)
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise MetainterfaceError(f"{name} must be a number in {span}, got {value!r}")
    value = float(value)
    bad = not math.isfinite(value)
    if low is not None:
        bad |= value <= low if low_open else value < low
    if high is not None:
        bad |= value >= high if high_open else value > high
    if bad:
        raise MetainterfaceError(f"{name} must be a finite number in {span}, got {value:g}")
    return value


def choice(name: str, value: Any, choices: Iterable[str]) -> str:
    """One of ``choices``."""
    options = list(choices)
    if value not in options:
        raise MetainterfaceError(f"{name} must be one of {', '.join(options)}, got {value!r}")
    return value
