"""What a design file records in SI units: the physical block (``physical``: the scale a
design was made or sized for) and the friction-law record (``target.friction``), read back
so that a command on that design.json need not be told them again."""

from __future__ import annotations

from typing import Any

from metainterface.physics.cell import Design


def friction_record(design: Design) -> dict[str, Any]:
    """The friction-law record of a design file (``target.friction``), {} if it has none."""
    target = design.extras.get("target")
    fric = target.get("friction") if isinstance(target, dict) else None
    return fric if isinstance(fric, dict) else {}


def recorded(design: Design, *keys: str) -> float | None:
    """The first of ``keys`` (SI, e.g. ``"radius_m"``) that the design file's physical block
    or, failing it, its friction record holds as a number; None if neither does."""
    for block in (design.extras.get("physical"), friction_record(design)):
        if isinstance(block, dict):
            for key in keys:
                value = block.get(key)
                if isinstance(value, int | float) and not isinstance(value, bool):
                    return float(value)
    return None
