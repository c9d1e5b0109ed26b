"""The forward models' registry: name -> model. ``design``, ``curve``, ``validate`` and the
CLI read it; :func:`register_model` adds a model of your own, :func:`get_model` reads a name,
a label as files record it, or an instance."""

from __future__ import annotations

import numpy as np
import torch

from metainterface._names import DEFAULT_MODEL
from metainterface.errors import MetainterfaceError
from metainterface.physics.cell import Design
from metainterface.physics.labels import from_label
from metainterface.physics.models import ForwardModel, Independent, Interacting

#: The registry: name -> model. ``design``, ``curve``, ``validate`` and the CLI read it.
MODELS: dict[str, ForwardModel] = {m.name: m for m in (Independent(), Interacting())}


def register_model(model: ForwardModel) -> ForwardModel:
    """Add ``model`` to the registry under ``model.name`` (replacing one of that name)."""
    if not isinstance(model, ForwardModel) or not model.name:
        raise MetainterfaceError("register_model takes a ForwardModel instance with a name")
    MODELS[model.name] = model
    return model


def get_model(model: str | ForwardModel | None = None) -> ForwardModel:
    """The model for a name, a label as files record it (``independent(adhesion=4e-05)``,
    :attr:`ForwardModel.label`) or an instance (None: the default, ``independent``)."""
    if model is None:
        return MODELS[DEFAULT_MODEL]
    if isinstance(model, ForwardModel):
        return model
    if isinstance(model, str) and model in MODELS:
        return MODELS[model]
    found = from_label(model, MODELS) if isinstance(model, str) else None
    if found is not None:
        return found
    raise MetainterfaceError(
        f"model must be one of {', '.join(MODELS)} (or a label such as "
        f"'independent(adhesion=4e-05)') or a ForwardModel, got {model!r}"
    )


def models_at(design: Design, p_star: np.ndarray) -> dict[str, np.ndarray]:
    """alpha (K,) of one design at the loads ``p_star`` (K,) under every registered model."""
    gamma, h = design.tensors(torch.float64)
    loads = torch.as_tensor(np.asarray(p_star, dtype=np.float64))[None]
    with torch.no_grad():
        return {
            name: m.alpha_at_loads(gamma, h, design.settings, loads)[0].numpy()
            for name, m in MODELS.items()
        }
