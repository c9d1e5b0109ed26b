"""The forward model that BEM results are compared with: one clearly separated plug-in point.

A model maps a Design to its response along a Delta sweep (a ``ModelCurve``); the validator
interpolates that curve at the BEM loads. ``independent`` is the paper's superposition of
non-interacting Sneddon asperities (``metainterface.physics``), ``interacting`` the same
with their elastic interaction (``physics.interaction``). Further models are plugged in with
``register_model("name", fn)`` and selected with ``validate_design(..., physics="name")``;
nothing else in the validation code changes.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import torch

from metainterface.errors import MetainterfaceError
from metainterface.physics.cell import Design
from metainterface.physics.curves import anchor, delta_grid, interp, sweep
from metainterface.physics.forward import PHYSICS, alpha_at_loads, asperity_sweep
from metainterface.physics.sneddon import area

#: Delta samples of the dense sweep that BEM loads are interpolated on.
N_DELTA = 8193


@dataclass(frozen=True)
class ModelCurve:
    """A model's response along its Delta sweep (float64 numpy).

    p_star: (K,) non-decreasing P* = P / E*, ending at the largest load the model reaches at
    Delta_max. alpha: (K,) contact-area fraction. asperity_alpha: (K, N) each asperity's
    contact area / A_nom (sums to alpha), or None if the model does not resolve it.
    """

    p_star: np.ndarray
    alpha: np.ndarray
    asperity_alpha: np.ndarray | None = None

    @property
    def p_star_max(self) -> float:
        """P* at Delta_max: the largest load the design reaches."""
        return float(self.p_star[-1])

    def at(self, p_star: np.ndarray) -> tuple[np.ndarray, np.ndarray | None]:
        """alpha (Q,) and asperity alpha (Q, N) (or None) at the loads ``p_star`` (Q,)."""
        xq = torch.as_tensor(np.asarray(p_star, dtype=np.float64))[None]
        xp = torch.as_tensor(self.p_star)[None]
        alpha = interp(xq, xp, torch.as_tensor(self.alpha)[None])[0].numpy()
        if self.asperity_alpha is None:
            return alpha, None
        per = torch.as_tensor(self.asperity_alpha).T  # (N, K): one row per asperity
        cols = interp(xq.expand(per.shape[0], -1), xp.expand(per.shape[0], -1), per)
        return alpha, cols.T.numpy()


ModelFunction = Callable[[Design], ModelCurve]


def independent_asperities(design: Design, n_delta: int = N_DELTA) -> ModelCurve:
    """The paper's model: summed Sneddon asperities, exact Macaulay bracket (sec. 2.2)."""
    gamma, h = design.tensors(torch.float64)
    s = design.settings
    delta = delta_grid(s, n_delta)
    sw = sweep(gamma, h, s, delta=delta)
    gap = delta[:, None] - anchor(h)  # (K, N)
    per = area(gamma, gap, s.radius) / s.nominal_area  # area() is 0 out of contact
    return ModelCurve(
        p_star=sw.p_star[0].numpy(), alpha=sw.alpha[0].numpy(), asperity_alpha=per.numpy()
    )


def interacting_asperities(design: Design, n_delta: int = N_DELTA) -> ModelCurve:
    """The same asperities with their elastic interaction (``physics.interaction``, issue 9)."""
    gamma, h = design.tensors(torch.float64)
    delta = delta_grid(design.settings, n_delta)
    sw, per = asperity_sweep(gamma, h, design.settings, physics="interacting", delta=delta)
    return ModelCurve(
        p_star=sw.p_star[0].numpy(), alpha=sw.alpha[0].numpy(), asperity_alpha=per[0].numpy()
    )


MODELS: dict[str, ModelFunction] = {
    "independent": independent_asperities,
    "interacting": interacting_asperities,
}


def register_model(name: str, fn: ModelFunction) -> None:
    """Make ``fn`` available as ``physics=name`` in the validation functions."""
    MODELS[name] = fn


def model_curve(design: Design, physics: str = "independent") -> ModelCurve:
    """The ModelCurve of ``design`` under the registered model ``physics``."""
    try:
        fn = MODELS[physics]
    except KeyError:
        raise MetainterfaceError(
            f"physics must be one of {', '.join(sorted(MODELS))}, got {physics!r}"
        ) from None
    curve = fn(design)
    if not (curve.p_star.size >= 2 and curve.p_star_max > 0):
        raise MetainterfaceError(f"model {physics!r} gives no load up to Delta_max")
    return curve


def models_at(design: Design, p_star: np.ndarray) -> dict[str, np.ndarray]:
    """alpha (K,) of ``design`` at the loads ``p_star`` (K,) under every built-in model.

    For reporting several models against one BEM path: the loads come from one model's
    P*_max, which the other may reach a little past or short of Delta_max, so each model's
    exact sweep is run as far as the loads need (``forward.alpha_at_loads``).
    """
    gamma, h = design.tensors(torch.float64)
    loads = torch.as_tensor(np.asarray(p_star, dtype=np.float64))[None]
    return {
        name: alpha_at_loads(gamma, h, design.settings, loads, physics=name)[0].numpy()
        for name in PHYSICS
    }
