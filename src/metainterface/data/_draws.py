"""What the topography categories share: the checks of their parameter classes and the
random draws they are built from (pure numpy; everything random comes from ``rng``)."""

from __future__ import annotations

import math
from dataclasses import fields
from typing import Any

import numpy as np

from metainterface.errors import MetainterfaceError
from metainterface.physics.cell import CellSettings

# -- parameter validation -------------------------------------------------------------------


def check_params(obj: Any) -> None:
    """Shared checks: every float finite and >= 0, every int >= 0 (names the field)."""
    for f in fields(obj):
        value = getattr(obj, f.name)
        if isinstance(value, bool):
            continue
        if isinstance(value, int):
            if value < 0:
                raise MetainterfaceError(f"{type(obj).__name__}.{f.name} must be >= 0, got {value}")
        elif isinstance(value, float) and not (math.isfinite(value) and value >= 0):
            raise MetainterfaceError(
                f"{type(obj).__name__}.{f.name} must be a finite number >= 0, got {value}"
            )


def require(cond: bool, obj: Any, text: str) -> None:
    if not cond:
        raise MetainterfaceError(f"{type(obj).__name__}: {text}")


# -- shared helpers -------------------------------------------------------------------------


def uniform(rng: np.random.Generator, low: float, high: float, size: Any) -> np.ndarray:
    """Uniform on [low, high)."""
    return low + (high - low) * rng.random(size)


def uniform_above(rng: np.random.Generator, low: float, high: float, size: Any) -> np.ndarray:
    """Uniform on (low, high]: strictly above ``low``."""
    return high - (high - low) * rng.random(size)


def full_gamma(rng: np.random.Generator, count: int, settings: CellSettings) -> np.ndarray:
    """(count, N) shape exponents uniform on [gamma_min, gamma_max)."""
    return uniform(rng, settings.gamma_min, settings.gamma_max, (count, settings.n_asperities))


def group_sizes(rng: np.random.Generator, count: int, low: int, high: int, n: int) -> np.ndarray:
    """(count,) integers uniform on [low, high], both clipped to [0, n]."""
    low, high = min(max(low, 0), n), min(max(high, 0), n)
    return rng.integers(low, max(low, high), size=count, endpoint=True)


def first(k: np.ndarray, n: int) -> np.ndarray:
    """(count, n) mask of the first k[i] columns of row i."""
    return np.arange(n) < k[:, None]


def anchor_group(h: np.ndarray, mask: np.ndarray) -> np.ndarray:
    """Subtract from the masked entries of each row their row minimum (rows with none: as is)."""
    low = np.where(mask, h, np.inf).min(axis=1, keepdims=True)
    return np.where(mask, h - np.where(np.isfinite(low), low, 0.0), h)


def truncated_normal_ppf(u: np.ndarray, mean: float, sd: float, high: float) -> np.ndarray:
    """Inverse CDF of a normal(mean, sd) truncated to [0, high], at u in [0, 1)."""
    from scipy import special  # where it is used: a few tenths of a second to import

    lo, hi = special.ndtr((0.0 - mean) / sd), special.ndtr((high - mean) / sd)
    return mean + sd * special.ndtri(lo + u * (hi - lo))


def truncated_exponential_ppf(u: np.ndarray, scale: float, high: float) -> np.ndarray:
    """Inverse CDF of an exponential(scale) truncated to [0, high], at u in [0, 1)."""
    return -scale * np.log1p(-u * -np.expm1(-high / scale))
