"""What a BEM validation of one design returns (:class:`ValidationResult`): the BEM and model
curves at the same P*, their errors, and the design's error to its target measured in BEM."""

from __future__ import annotations

import functools
from dataclasses import dataclass
from typing import Any

import numpy as np
import torch

from metainterface import _checks
from metainterface._names import DEFAULT_ENGINE
from metainterface.errors import MetainterfaceError
from metainterface.physics.cell import Design
from metainterface.physics.grid_error import grid_curve_error
from metainterface.physics.models import ForwardModel, ModelCurve
from metainterface.physics.registry import models_at
from metainterface.validation.heightmap import HeightMap


@dataclass(frozen=True, repr=False)
class ValidationResult:
    """BEM against model for one design, at K loads on an M x M grid.

    Attributes
    ----------
    name, design, grid, model, tolerance, max_iter
        What was checked, and how: the design's name and the design, M, the forward model
        compared with, the solver's tolerance and iteration limit.
    p_star : ndarray, shape (K,)
        Mean pressures P* = P / E*, ascending.
    alpha_bem, alpha_model : ndarray, shape (K,)
        Contact-area fractions from the BEM (contact edges to sub-pixel accuracy) and the
        model at those pressures.
    alpha_bem_pixels : ndarray, shape (K,)
        The BEM's plain count of grid points in contact, / M^2.
    p_max : ndarray, shape (K,)
        Largest local pressure p / E*.
    asperity_alpha_bem, asperity_alpha_model : ndarray, shape (K, N)
        Contact area of each asperity / A_nom (the model's None if the model does not
        resolve asperities).
    residual, seconds : ndarray, shape (K,)
        Solver error and wall time [s] per load.
    pressure : ndarray, shape (M, M)
        p / E* at the largest load.
    heights : HeightMap
        The cell's height map.
    curve : ModelCurve
        The model's dense curve.
    pressures, gaps : ndarray, shape (K, M, M), or None
        p / E* and the gap [units of R] at every load, kept when solved with
        ``fields=True`` (written by ``write_result`` as fields.nc).
    engine : str
        The contact solver that made it ("torch" or "tamaas").
    """

    name: str
    design: Design
    grid: int
    model: ForwardModel
    tolerance: float
    max_iter: int
    p_star: np.ndarray
    alpha_bem: np.ndarray
    alpha_model: np.ndarray
    alpha_bem_pixels: np.ndarray
    p_max: np.ndarray
    asperity_alpha_bem: np.ndarray
    asperity_alpha_model: np.ndarray | None
    residual: np.ndarray
    seconds: np.ndarray
    pressure: np.ndarray
    heights: HeightMap
    curve: ModelCurve
    pressures: np.ndarray | None = None
    gaps: np.ndarray | None = None
    engine: str = DEFAULT_ENGINE

    @property
    def rel_err(self) -> np.ndarray:
        """(K,) alpha_bem / alpha_model - 1."""
        return self.alpha_bem / self.alpha_model - 1.0

    def __repr__(self) -> str:
        return (
            f"ValidationResult({self.name!r}, {len(self.p_star)} loads on {self.grid}x{self.grid}, "
            f"model {self.model.label}: max |rel_err| {100 * self.max_rel_err_upper:.3g} % "
            f"over the upper half, {100 * self.max_rel_err:.3g} % over all loads)"
        )

    @functools.cached_property
    def alpha_by_model(self) -> dict[str, np.ndarray]:
        """{model name: alpha (K,)} of every registered model at this result's loads."""
        return models_at(self.design, self.p_star)

    @property
    def upper_half(self) -> slice:
        """The upper half of the loads (indices K // 2 .. K - 1)."""
        return slice(len(self.p_star) // 2, None)

    @property
    def max_rel_err_upper(self) -> float:
        """Largest abs(rel_err) over the upper half of the loads."""
        return float(np.abs(self.rel_err[self.upper_half]).max())

    @property
    def max_rel_err(self) -> float:
        """Largest abs(rel_err) over all loads."""
        return float(np.abs(self.rel_err).max())

    @property
    def max_rel_err_upper_pixels(self) -> float:
        """``max_rel_err_upper`` with the BEM's plain count of grid points in contact."""
        return float(np.abs(self.alpha_bem_pixels / self.alpha_model - 1.0)[self.upper_half].max())

    def target_error(self, alpha: np.ndarray) -> float | None:
        """The package's curve error (``physics.metrics.curve_error``) of
        alpha (K,), measured at this result's loads, against the design's target; or None
        without a target.

        Measured as ``design`` measures, by
        ``physics.grid_error.grid_curve_error``: on the target's uniform
        grid of ``ERROR_POINTS`` pressures, with
        the model's exact alpha there times alpha / alpha_model interpolated between the
        loads (a ratio that is not finite counts as 1; so the model's own alpha scores
        exactly the model's design error, and the BEM's differs only by the measured ratio);
        coverage is the design's P*_max over the target's largest load.
        """
        target = design_target(self.design)
        if target is None:
            return None
        gamma, h = self.design.tensors(torch.float64)
        err, _ = grid_curve_error(
            gamma.numpy(),
            h.numpy(),
            self.design.settings,
            target,
            self.model,
            ratio=(self.p_star, alpha / self.alpha_model),
        )
        return float(err[0])

    def target_errors(self) -> tuple[float, float] | None:
        """``target_error`` of BEM and model: (BEM, model), or None.

        The BEM figure is what the manufactured surface would show; the model one is the
        design's own claim, the same figure ``design`` reported with this model.
        """
        bem = self.target_error(self.alpha_bem)
        if bem is None:
            return None
        return bem, self.target_error(self.alpha_model)  # type: ignore[return-value]

    @property
    def coverage(self) -> float | None:
        """The fraction of the target's load range the design reaches (None: no target)."""
        target = design_target(self.design)
        if target is None:
            return None
        return float(min(1.0, self.p_star[-1] / target[0][-1]))

    @property
    def idle(self) -> tuple[int, ...]:
        """Indices of the asperities that carry no load within Delta_max and the target's
        load range."""
        from metainterface.physics.curves import idle_mask

        gamma, h = self.design.tensors(torch.float64)
        target = design_target(self.design)
        limit = None if target is None else torch.tensor([target[0][-1]], dtype=torch.float64)
        mask = idle_mask(gamma, h, self.design.settings, limit, sweep_fn=self.model.sweep)
        return tuple(int(i) for i in np.flatnonzero(mask[0].numpy()))

    @property
    def carrying(self) -> int:
        """The number of load-carrying asperities."""
        return self.design.n_asperities - len(self.idle)

    def summary(self) -> dict[str, Any]:
        """JSON-ready scalars (with the target errors if the design carries a target)."""
        errors = self.target_errors()
        extra = (
            {}
            if errors is None
            else {"target_error_bem": errors[0], "target_error_model": errors[1]}
        )
        if errors is not None:
            extra["coverage"] = self.coverage
        extra["carrying_asperities"] = self.carrying
        return {
            "name": self.name,
            "engine": self.engine,
            "loads": len(self.p_star),
            "grid": self.grid,
            "model": self.model.label,
            "p_star_max": float(self.p_star[-1]),
            "max_rel_err_upper_half": self.max_rel_err_upper,
            "max_rel_err": self.max_rel_err,
            "max_rel_err_upper_half_pixels": self.max_rel_err_upper_pixels,
            "max_local_pressure": float(self.p_max.max()),
            "max_residual": float(self.residual.max()),
            "bem_seconds": float(self.seconds.sum()),
            **extra,
        }


def design_target(design: Design) -> tuple[np.ndarray, np.ndarray] | None:
    """The design file's optional "target": {"p_star": [...], "alpha": [...]} as arrays."""
    target = design.extras.get("target")
    if target is None:
        return None
    if not (isinstance(target, dict) and "p_star" in target and "alpha" in target):
        raise MetainterfaceError('target must be an object {"p_star": [...], "alpha": [...]}')
    p = _checks.vector("target.p_star", target["p_star"])
    a = _checks.vector("target.alpha", target["alpha"])
    if p.ndim != 1 or p.shape != a.shape or p.size < 2:
        raise MetainterfaceError(
            "target.p_star and target.alpha must be lists of one length (>= 2 points)"
        )
    return p, a
