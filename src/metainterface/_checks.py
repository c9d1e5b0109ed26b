"""Checks of user-facing values, shared by the Python API and the command line.

Each returns the value normalised (int or float) or raises MetainterfaceError with one line
that names the argument and the allowed range. Every error carries the argument's
name (``MetainterfaceError.argument``); the CLI shows it under its ``--option`` name.

Sizes with no natural upper bound (starts, steps, grid points, samples) are bounded by what a
request costs: :func:`affordable` refuses one whose memory (or disk) need exceeds what this
machine has, saying how much it would need.
"""

from __future__ import annotations

import math
import numbers
import os
import shutil
from collections.abc import Iterable
from pathlib import Path
from typing import Any

import numpy as np

from metainterface.errors import MetainterfaceError

#: Largest seed: numpy and torch take unsigned 64-bit seeds, torch refuses more than 2**63 - 1.
MAX_SEED = 2**63 - 1
#: Share of the physical memory a single request may claim.
MEMORY_SHARE = 0.5


def _range(low: float | None, high: float | None, low_open: bool, high_open: bool) -> str:
    lo = "(" if low_open or low is None else "["
    hi = ")" if high_open or high is None else "]"

    def show(x: float | None, inf: str) -> str:
        if x is None:
            return inf
        return f"{x}" if isinstance(x, int) and abs(x) < 10**20 else f"{x:g}"

    return f"{lo}{show(low, '-inf')}, {show(high, 'inf')}{hi}"


def whole(name: str, value: Any, *, low: int | None = None, high: int | None = None) -> int:
    """An integer in [low, high] (bools and non-integral numbers refused)."""
    ok = isinstance(value, numbers.Integral) and not isinstance(value, bool)
    if not ok:
        raise MetainterfaceError(
            f"{name} must be a whole number in {_range(low, high, False, False)}, got {value!r}",
            argument=name,
        )
    value = int(value)
    if (low is not None and value < low) or (high is not None and value > high):
        raise MetainterfaceError(
            f"{name} must be a whole number in {_range(low, high, False, False)}, got {value}",
            argument=name,
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
        raise MetainterfaceError(f"{name} must be a number in {span}, got {value!r}", argument=name)
    value = float(value)
    bad = not math.isfinite(value)
    if low is not None:
        bad |= value <= low if low_open else value < low
    if high is not None:
        bad |= value >= high if high_open else value > high
    if bad:
        raise MetainterfaceError(
            f"{name} must be a finite number in {span}, got {value:g}", argument=name
        )
    return value


def choice(name: str, value: Any, choices: Iterable[str]) -> str:
    """One of ``choices``."""
    options = list(choices)
    if value not in options:
        raise MetainterfaceError(
            f"{name} must be one of {', '.join(options)}, got {value!r}", argument=name
        )
    return value


def seed(value: Any, name: str = "seed") -> int:
    """A random seed: a whole number in [0, 2**63 - 1]."""
    return whole(name, value, low=0, high=MAX_SEED)


def vector(name: str, values: Any, *, size: int | None = None) -> np.ndarray:
    """A non-empty 1-D float64 array of finite numbers (strings and bools refused)."""
    items = values.tolist() if hasattr(values, "tolist") else values  # numpy, torch
    if isinstance(items, str | bytes) or not isinstance(items, Iterable):
        raise MetainterfaceError(f"{name} must be a list of numbers", argument=name)
    items = list(items)
    for i, v in enumerate(items):
        if isinstance(v, bool) or not isinstance(v, numbers.Real):
            raise MetainterfaceError(
                f"{name}[{i}] must be a number, got {v!r}" + (" (a string)" * isinstance(v, str)),
                argument=name,
            )
    arr = np.asarray(items, dtype=np.float64)
    if arr.ndim != 1 or arr.size == 0:
        raise MetainterfaceError(f"{name} must be a non-empty 1-D list of numbers", argument=name)
    bad = np.flatnonzero(~np.isfinite(arr))
    if bad.size:
        raise MetainterfaceError(
            f"{name}[{int(bad[0])}] is {arr[bad[0]]}; values must be finite", argument=name
        )
    if size is not None and arr.size != size:
        raise MetainterfaceError(f"{name} must have {size} values, got {arr.size}", argument=name)
    return arr


def _gib(nbytes: float) -> str:
    return f"{nbytes / 2**30:.3g} GiB" if nbytes >= 2**27 else f"{nbytes / 2**20:.3g} MiB"


def memory_total() -> int:
    """Physical memory of this machine [bytes] (a large figure where it cannot be read)."""
    try:
        return int(os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES"))
    except (ValueError, OSError, AttributeError):  # pragma: no cover - non-POSIX
        return 2**40


def affordable(name: str, value: Any, nbytes: float, *, what: str = "") -> None:
    """Refuse a request that would need more than half this machine's memory.

    ``nbytes``: the memory the request ``name = value`` would claim. The message says what
    it would cost and names the argument, so the user knows what to lower.
    """
    budget = MEMORY_SHARE * memory_total()
    if nbytes > budget:
        raise MetainterfaceError(
            f"{name} = {value} would need about {_gib(nbytes)} of memory{what}, more than "
            f"{_gib(budget)} (half of this machine's)",
            argument=name,
        )


def disk_room(name: str, value: Any, nbytes: float, folder: str | os.PathLike[str]) -> None:
    """Refuse a request whose output (``nbytes``) would not fit on the disk of ``folder``."""
    here = Path(folder)
    while not here.exists() and here != here.parent:
        here = here.parent
    try:
        free = shutil.disk_usage(here).free
    except OSError:
        return
    if nbytes > free:
        raise MetainterfaceError(
            f"{name} = {value} would write about {_gib(nbytes)}, more than the "
            f"{_gib(free)} free on {here}",
            argument=name,
        )
