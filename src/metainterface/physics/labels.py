"""Forward models named by their labels, as output files record them.

A model's label is its registered name and the options that differ from their defaults
(``ForwardModel.label``): ``independent``, ``interacting(curvature=True)``,
``independent(adhesion=4.1666666667e-05)``. Reading one back gives the model a design was
made with, adhesion included, for the commands that take a design file.
"""

from __future__ import annotations

import ast
import re
from collections.abc import Mapping
from dataclasses import fields, is_dataclass, replace
from typing import Any


def from_label(label: str, registry: Mapping[str, Any]) -> Any | None:
    """The model of ``registry`` with the options ``label`` names, or None where it names
    no registered model, an option it lacks or a value that is not a literal; a value the
    model refuses raises its MetainterfaceError."""
    match = re.fullmatch(r"\s*(\w+)\((.*)\)\s*", label)
    if match is None or match[1] not in registry or not is_dataclass(registry[match[1]]):
        return None
    base = registry[match[1]]
    names = {f.name for f in fields(base)}
    opts: dict[str, Any] = {}
    for item in filter(None, (part.strip() for part in match[2].split(","))):
        key, _, text = item.partition("=")
        try:
            value = ast.literal_eval(text.strip())
        except (ValueError, SyntaxError):
            return None
        if key.strip() not in names or not isinstance(value, bool | int | float | str):
            return None
        opts[key.strip()] = value
    # the model checks its own options: a value out of range is its one-line error
    return replace(base, **opts)
