"""The forward model a design uses for adhesive targets (issue 38).

Adhesion is a property of the forward model (``Independent(adhesion=w)``): a friction law
converted with a work of adhesion (``Target.from_friction(work_of_adhesion=...)``) carries
w / (E* R) in ``meta["friction"]["adhesion"]``, and the design step's model takes it.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from typing import Any

from metainterface.errors import MetainterfaceError
from metainterface.physics.models import ForwardModel


def target_adhesion(target: Any) -> float:
    """w / (E* R) that a target was converted with (0: none or not a friction law)."""
    meta = getattr(target, "meta", None) or {}
    friction = meta.get("friction") if isinstance(meta, dict) else None
    if not isinstance(friction, dict):
        return 0.0
    return float(friction.get("adhesion", 0.0) or 0.0)


def model_for_targets(model: ForwardModel, targets: Sequence[Any]) -> ForwardModel:
    """``model`` with the adhesion its targets were converted with.

    Targets designed in one batch share one model: their adhesions must agree (or be 0).
    A model given with an adhesion of its own keeps it; one that differs from a target's
    is an error (the law would be designed for another contact).
    """
    values = {round(target_adhesion(t), 15) for t in targets} - {0.0}
    if not values:
        return model
    if len(values) > 1:
        raise MetainterfaceError(
            "targets designed together must share one work of adhesion (relative to E* R), "
            f"got {sorted(values)}; design them separately"
        )
    w = values.pop()
    if model.adhesion:
        if abs(model.adhesion - w) > 1e-9 * w:
            raise MetainterfaceError(
                f"the model's adhesion {model.adhesion:g} differs from the target's {w:g} "
                "(work of adhesion / (E* R)); give one of them",
                argument="model",
            )
        return model
    if not dataclasses.is_dataclass(model) or "adhesion" not in {
        f.name for f in dataclasses.fields(model)
    }:
        raise MetainterfaceError(
            f"model {model.label!r} does not take adhesion; use 'independent' or 'interacting'",
            argument="model",
        )
    return dataclasses.replace(model, adhesion=w)
