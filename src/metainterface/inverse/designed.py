"""What the design loop returns for one target (before the public API adds its checks)."""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from metainterface.inverse.targets import Target
from metainterface.physics.cell import CellSettings
from metainterface.physics.models import ForwardModel
from metainterface.physics.registry import get_model


@dataclass(frozen=True)
class DesignResult:
    """A designed cell for one target: gamma, h (N,); relative curve error; wall seconds."""

    target: Target
    method: str
    gamma: np.ndarray
    h: np.ndarray
    error: float
    seconds: float
    initial_error: float
    settings: CellSettings
    model: ForwardModel = field(default_factory=get_model)
    start: int = 0  # which start won: 0 = the zero-shot prediction (surrogate) or first start
    fallback: bool = False  # the design came from the surrogate method's fallback multistart
    notes: tuple[str, ...] = ()  # what the pipeline decided for the user (e.g. no surrogate)
    # robust design: the rms relative error over the perturbed copies refined against
    robust_error: float | None = None
    # printable heights: errors before the snap to the layer grid, after it, and the step
    quantisation: dict | None = None
    # which network (and view of the target) made the zero-shot design; "" for baselines
    zero_shot_from: str = ""

    def redesigned(self, gamma: np.ndarray, h: np.ndarray, error: float, note: str) -> DesignResult:
        """This result with another design (gamma, h (N,), its error) and a note on why."""
        return replace(self, gamma=gamma.copy(), h=h.copy(), error=error, notes=(*self.notes, note))
