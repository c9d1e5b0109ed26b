"""What the public functions return: numpy curves and design results that draw themselves."""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
import torch

from metainterface.errors import MetainterfaceError
from metainterface.inverse.targets import Target
from metainterface.physics.cell import Design
from metainterface.physics.limits import PressureCheck
from metainterface.physics.models import ForwardModel, get_model

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

#: Delta samples of a curve when none are asked for.
CURVE_STEPS = 256


def _axes(ax: Axes | None) -> Axes:
    """The axes to draw on: the given one, or a new pyplot figure's (shown inline in a
    notebook)."""
    if ax is not None:
        return ax
    import matplotlib.pyplot as plt

    return plt.subplots(figsize=(5.0, 3.6), layout="constrained")[1]


@dataclass(frozen=True, repr=False)
class Curve:
    """The response of one design along its indentation sweep, as numpy arrays.

    delta: (K,) global indentation Delta [units of R], from 0 to Delta_max.
    p_star: (K,) dimensionless pressure P* = P / E*. alpha: (K,) contact-area fraction
    A_real / A_nom. stiffness: (K,) S* = dP*/dalpha. model: the forward model's label.
    notes: what the user should know about the result (asperities that never touch).
    """

    delta: np.ndarray
    p_star: np.ndarray
    alpha: np.ndarray
    stiffness: np.ndarray
    model: str = "independent"
    notes: tuple[str, ...] = ()

    @property
    def p_star_max(self) -> float:
        """P* at Delta_max: the largest load of the design."""
        return float(self.p_star[-1])

    @property
    def alpha_max(self) -> float:
        """alpha at Delta_max."""
        return float(self.alpha[-1])

    def columns(self) -> dict[str, np.ndarray]:
        """{'delta', 'p_star', 'alpha', 'stiffness'}: the CSV columns of ``curve``."""
        return {
            "delta": self.delta,
            "p_star": self.p_star,
            "alpha": self.alpha,
            "stiffness": self.stiffness,
        }

    def plot(self, ax: Axes | None = None, *, label: str | None = None) -> Axes:
        """Draw alpha(P*) on ``ax`` (default: a new figure); returns the axes."""
        from metainterface.plots import draw_curve

        return draw_curve(_axes(ax), self, label=label or self.model)

    def __repr__(self) -> str:
        return (
            f"Curve({self.p_star.size} points, {self.model}, P*_max={self.p_star_max:.4g}, "
            f"alpha_max={self.alpha_max:.4g})"
        )


def design_curve(
    design: Design,
    model: str | ForwardModel | None = None,
    *,
    steps: int = CURVE_STEPS,
    smooth: float | None = None,
) -> Curve:
    """The :class:`Curve` of a design under a forward model (float64, no gradients)."""
    m = get_model(model)
    with torch.no_grad():
        sw = m.design_sweep(design, n_delta=steps, smooth=smooth)
    delta = sw.delta if sw.delta.dim() == 1 else sw.delta[0]
    for name in ("p_star", "alpha", "stiffness"):
        if not torch.isfinite(getattr(sw, name)[0]).all():
            raise MetainterfaceError(
                f"the {m.label} model gives a non-finite {name} for this design"
                + (f" with smooth = {smooth:g}" if smooth is not None else "")
                + "; the curve would be wrong, so none is returned"
            )
    return Curve(
        delta=delta.numpy().copy(),
        p_star=sw.p_star[0].numpy().copy(),
        alpha=sw.alpha[0].numpy().copy(),
        stiffness=sw.stiffness[0].numpy().copy(),
        model=m.label,
        notes=idle_notes(design),
    )


def idle_notes(design: Design) -> tuple[str, ...]:
    """A note on the asperities more than Delta_max above the lowest tip, if any."""
    idle = design.idle
    if not idle.size:
        return ()
    return (
        f"{idle.size} of {design.n_asperities} asperities (index {', '.join(map(str, idle))}) "
        "sit more than Delta_max above the lowest tip and never touch",
    )


@dataclass(frozen=True, repr=False)
class DesignResult:
    """A designed unit cell for one target.

    design: the cell (numpy gamma, h (N,), settings). error: relative curve error
    ||alpha - alpha_target||_2 / ||alpha_target||_2 at the target's pressures (0.01 = 1 %).
    initial_error: the same before refinement (the zero-shot prediction's, or the best
    start's). method: surrogate, multistart or hertz. seconds: wall time per target.
    model: the forward model designed with. start: which start won (0 = the zero-shot
    prediction). fallback: the design came from the fallback multistart. notes: what the
    pipeline decided on the user's behalf. pressure: the peak-pressure check, when a limit
    was given.
    """

    target: Target
    design: Design
    error: float
    initial_error: float
    method: str
    seconds: float
    model: ForwardModel = field(default_factory=get_model)
    start: int = 0
    fallback: bool = False
    notes: tuple[str, ...] = ()
    pressure: PressureCheck | None = None

    @property
    def origin(self) -> str:
        """Which start the design came from, in words (random starts numbered from 1)."""
        if self.fallback:
            return f"fallback multistart, random start {self.start + 1}"
        if self.method != "surrogate":
            return f"random start {self.start + 1}"
        return "zero-shot" if self.start == 0 else f"hedge start {self.start}"

    def curve(self, steps: int = CURVE_STEPS) -> Curve:
        """The design's curve under the model it was designed with."""
        return design_curve(self.design, self.model, steps=steps)

    def plot(self, ax: Axes | None = None) -> Axes:
        """Draw the target and the design's alpha(P*) on ``ax`` (default: a new figure)."""
        from metainterface.plots import draw_curve

        ax = draw_curve(
            _axes(ax),
            self.curve(),
            label=f"{self.method}: {_percent(self.error)}",
            target=self.target,
        )
        ax.set_title(self.target.name)
        return ax

    def figure(self) -> Figure:
        """The full design figure: curves, stiffness, parameters, the cell seen from above."""
        from metainterface.plots import plot_design

        return plot_design(self, self.curve())

    def record(self) -> dict[str, Any]:
        """What design.json stores about how the design was made."""
        t = self.target
        return {
            "target": {
                "name": t.name,
                "source": t.source,
                "p_star": t.p_star.tolist(),
                "alpha": t.alpha.tolist(),
                **t.meta,
            },
            "method": self.method,
            "model": self.model.label,
            "winning_start": self.origin,
            "relative_error": self.error,
            "zero_shot_error": self.initial_error,
            "seconds": self.seconds,
            **({"notes": list(self.notes)} if self.notes else {}),
            **({"pressure_check": self.pressure.to_dict()} if self.pressure else {}),
        }

    def save(self, folder: str | os.PathLike[str], **extra: Any) -> Path:
        """Write design.json, target.csv, curve.csv and design.png into ``folder``; ``extra``
        keys go into design.json. Returns the path of design.json."""
        from metainterface.api.outputs import write_design_outputs

        return write_design_outputs(Path(folder), self, **extra)

    def __repr__(self) -> str:
        note = f", note: {self.notes[0]}" if self.notes else ""
        return (
            f"DesignResult(target={self.target.name!r}, method={self.method!r}, "
            f"model={self.model.label!r}, error={_percent(self.error)}, "
            f"zero-shot {_percent(self.initial_error)}, {self.seconds:.2f} s, "
            f"design={self.design!r}{note})"
        )


def _percent(x: float) -> str:
    """A relative error in per cent with significant digits (0.0097 % not 0.00 %)."""
    return f"{100 * x:.3g} %"
