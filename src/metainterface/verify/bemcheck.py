"""A BEM check's result: the design's contact-area curve in BEM against its target, with
the check's own accuracy, and the curve error it is measured by."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np


def curve_error(alpha: np.ndarray, alpha_target: np.ndarray) -> float:
    """||alpha - alpha_target||_2 / ||alpha_target||_2 (0 for a zero target)."""
    norm = float(np.linalg.norm(alpha_target))
    return float(np.linalg.norm(alpha - alpha_target)) / norm if norm > 0 else 0.0


@dataclass(frozen=True, repr=False)
class BemCheck:
    """A design's contact-area curve in BEM against its target.

    Attributes
    ----------
    p_star : ndarray, shape (K,)
        The loads P* = P / E*, ascending, within the target's range and the design's reach.
    alpha_bem, alpha_model, alpha_target : ndarray, shape (K,)
        Contact-area fraction in BEM (extrapolated from ``grid`` and ``coarse_grid`` where
        there is one), from the forward model, and the target's (interpolated) at those loads.
    bem_error, model_error : float
        Relative curve error to the target of the BEM and of the model at these loads.
    grid : int
        M, grid points per cell side.
    accuracy : float or None
        The check's own accuracy: how far ``bem_error`` may be off for the grids' sake (the
        extrapolation's spread, ``verify.accuracy``), on the same scale; None where it was
        not estimated (an adhesive check, or a grid with no coarser one).
    coarse_grid : int or None
        The second grid (M / 2) the accuracy and extrapolation come from.
    alpha_grid, alpha_coarse : ndarray, shape (K,), or None
        The BEM's alpha as read on ``grid`` and on ``coarse_grid``.
    held_out : bool
        The loads are the interleaved set (k - 1/2) / K, which no correction fitted; False:
        the check's own k / K (those a correction fits).
    engine, device : str
        The contact solver and where it ran.
    seconds : float
        Wall time of the BEM solve [s].
    max_error : float
        The threshold the design is trusted within.
    notes : tuple of str
        What the check says beside its figures.
    adhesion : float
        The work of adhesion w [E* R] of an adhesive design's check (0: adhesionless): its
        loads are the states of the JKR-limit BEM that a rising force reaches
        (``verify.adhesive``).
    """

    p_star: np.ndarray
    alpha_bem: np.ndarray
    alpha_model: np.ndarray
    alpha_target: np.ndarray
    bem_error: float
    model_error: float
    grid: int
    engine: str
    device: str
    seconds: float
    max_error: float = 0.02
    notes: tuple[str, ...] = field(default=())
    adhesion: float = 0.0
    accuracy: float | None = None
    coarse_grid: int | None = None
    alpha_grid: np.ndarray | None = None
    alpha_coarse: np.ndarray | None = None
    held_out: bool = False

    @property
    def ok(self) -> bool:
        """The BEM error is within ``max_error``."""
        return self.bem_error <= self.max_error

    @property
    def rel_err(self) -> np.ndarray:
        """(K,) alpha_bem / alpha_model - 1: the model's own error at each load."""
        return self.alpha_bem / self.alpha_model - 1.0

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready: the scalars and the per-load values."""
        return {
            "bem_error": self.bem_error,
            "model_error": self.model_error,
            "max_error": self.max_error,
            "ok": self.ok,
            "grid": self.grid,
            "loads": int(self.p_star.size),
            "engine": self.engine,
            "device": self.device,
            "seconds": self.seconds,
            "accuracy": self.accuracy,
            "load_set": "(k - 1/2) / K, held out" if self.held_out else "k / K",
            "p_star": self.p_star.tolist(),
            "alpha_bem": self.alpha_bem.tolist(),
            "alpha_model": self.alpha_model.tolist(),
            "alpha_target": self.alpha_target.tolist(),
            **(
                {
                    "coarse_grid": self.coarse_grid,
                    "alpha_grid": self.alpha_grid.tolist(),
                    "alpha_coarse": self.alpha_coarse.tolist(),
                }
                if self.coarse_grid is not None
                and self.alpha_grid is not None
                and self.alpha_coarse is not None
                else {}
            ),
            **({"notes": list(self.notes)} if self.notes else {}),
            **({"adhesion": self.adhesion} if self.adhesion else {}),
        }

    def error_text(self) -> str:
        """'0.12 % +- 0.15 %': the BEM error and its accuracy (the error alone where the
        accuracy was not estimated)."""
        return f"{100 * self.bem_error:.3g} %{self.accuracy_text()}"

    def accuracy_text(self) -> str:
        """' +- 0.15 %', or '' where the accuracy was not estimated."""
        return "" if self.accuracy is None else f" +- {100 * self.accuracy:.2g} %"

    def __repr__(self) -> str:
        grids = f"{self.grid}x{self.grid}"
        if self.coarse_grid is not None:
            grids += f" and {self.coarse_grid}x{self.coarse_grid}"
        where = "held-out " if self.held_out else ""
        return (
            f"BemCheck(BEM error {self.error_text()} (model {100 * self.model_error:.3g}"
            f" %) at {self.p_star.size} {where}loads on {grids}, {self.engine}, "
            f"{self.seconds:.2g} s{'' if self.ok else ', above ' + f'{100 * self.max_error:g} %'})"
        )
