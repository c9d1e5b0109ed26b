"""Strict JSON out: no NaN or Infinity tokens, which other JSON readers refuse.

A non-finite float becomes null (JSON's "no value"), in numpy scalars and arrays too.
"""

from __future__ import annotations

import json
import math
from typing import Any

import numpy as np


def finite_or_none(obj: Any) -> Any:
    """``obj`` with every non-finite float replaced by None (dicts, lists, tuples, numpy)."""
    if isinstance(obj, dict):
        return {k: finite_or_none(v) for k, v in obj.items()}
    if isinstance(obj, list | tuple):
        return [finite_or_none(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return finite_or_none(obj.tolist())
    if isinstance(obj, np.generic):
        obj = obj.item()
    if isinstance(obj, float) and not math.isfinite(obj):
        return None
    return obj


def dumps(obj: Any, **kwargs: Any) -> str:
    """json.dumps with non-finite numbers as null and ``allow_nan=False`` as a guard."""
    return json.dumps(finite_or_none(obj), allow_nan=False, **kwargs)
