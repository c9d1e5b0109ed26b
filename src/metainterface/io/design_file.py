"""The design file format, metainterface/design-v1, read and written by every command.

    {"format": "metainterface/design-v1", "gamma": [...], "h": [...], "radius": 1.0,
     "delta_max": 0.02, "gamma_bounds": [1.8, 4.0], "e_star": 1.0}

gamma and h are required (h dimensionless, in units of R; asperity k in lattice cell
(k // n, k % n)); the rest default to the paper's values. Any other key is kept as it is
when the file is read and written again.
"""

from __future__ import annotations

import json
import os
from pathlib import Path
from typing import Any

from metainterface.errors import MetainterfaceError
from metainterface.io.atomic import write_text
from metainterface.io.provenance import provenance
from metainterface.physics.cell import CellSettings, Design

FORMAT = "metainterface/design-v1"
_CORE_KEYS = {"format", "gamma", "h", "radius", "delta_max", "gamma_bounds", "e_star"}


def design_from_dict(data: Any, *, source: str = "design") -> Design:
    """Build and validate a Design from a parsed design-v1 mapping."""
    if not isinstance(data, dict):
        raise MetainterfaceError(f"{source}: expected a JSON object with keys gamma and h")
    fmt = data.get("format", FORMAT)
    if fmt != FORMAT:
        raise MetainterfaceError(f"{source}: unknown format {fmt!r}, expected {FORMAT!r}")
    for key in ("gamma", "h"):
        if key not in data:
            raise MetainterfaceError(f"{source}: missing required field {key!r}")
        if not isinstance(data[key], list):
            raise MetainterfaceError(f"{source}: field {key!r} must be a list of numbers")
    bounds = data.get("gamma_bounds", [1.8, 4.0])
    if not (isinstance(bounds, list) and len(bounds) == 2):
        raise MetainterfaceError(f"{source}: gamma_bounds must be a list [gamma_min, gamma_max]")
    try:
        settings = CellSettings(
            n_asperities=len(data["gamma"]),
            radius=data.get("radius", 1.0),
            e_star=data.get("e_star", 1.0),
            delta_max=data.get("delta_max", 0.02),
            gamma_min=bounds[0],
            gamma_max=bounds[1],
        )
        extras = {k: v for k, v in data.items() if k not in _CORE_KEYS}
        return Design(gamma=data["gamma"], h=data["h"], settings=settings, extras=extras)
    except MetainterfaceError as exc:
        raise MetainterfaceError(f"{source}: {exc}") from None


def design_to_dict(design: Design, **extra: Any) -> dict[str, Any]:
    """The design-v1 mapping of a design; ``extra`` keys are added (they override extras)."""
    s = design.settings
    out: dict[str, Any] = {
        "format": FORMAT,
        "gamma": [float(g) for g in design.gamma],
        "h": [float(v) for v in design.h],
        "radius": s.radius,
        "delta_max": s.delta_max,
        "gamma_bounds": [s.gamma_min, s.gamma_max],
        "e_star": s.e_star,
    }
    out.update(design.extras)
    out.update(extra)
    return out


def load_design(path: str | os.PathLike[str]) -> Design:
    """Read and validate a design file; errors name the file and the field."""
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise MetainterfaceError(f"{path}: file not found") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise MetainterfaceError(f"{path}: cannot read ({exc})") from None
    try:
        data = json.loads(text)
    except json.JSONDecodeError as exc:
        raise MetainterfaceError(
            f"{path}: malformed JSON at line {exc.lineno} column {exc.colno}: {exc.msg}"
        ) from None
    return design_from_dict(data, source=str(path))


def save_design(path: str | os.PathLike[str], design: Design, **extra: Any) -> Path:
    """Atomically write a design file; records provenance unless the design carries one."""
    data = design_to_dict(design, **extra)
    data.setdefault("provenance", provenance())
    return write_text(path, json.dumps(data, indent=2) + "\n")
