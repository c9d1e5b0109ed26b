"""A design's curve as numpy (:class:`Curve`, :func:`design_curve`) and what the curve says
about its asperities (which carry load, which stay idle), with the figure helpers the
results share."""

from __future__ import annotations

import functools
import io
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
import torch

from metainterface.errors import MetainterfaceError
from metainterface.physics.cell import Design
from metainterface.physics.models import ForwardModel
from metainterface.physics.registry import get_model

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

#: Delta samples of a curve when none are asked for.
CURVE_STEPS = 256
#: Most points of a target curve stored in design.json (the full one goes to target.csv
#: only when asked): small whatever the size of the user's file (~60 kB at most), yet
#: the built-in and typical measured targets are kept whole, so errors measured later to
#: the stored target (tolerance, validate) equal the one the design reported.
RECORD_POINTS = 1024


def _axes(ax: Axes | None) -> Axes:
    """The axes to draw on: the given one, or a new pyplot figure's (shown inline in a
    notebook)."""
    if ax is not None:
        return ax
    import matplotlib.pyplot as plt

    return plt.subplots(figsize=(5.0, 3.6), layout="constrained")[1]


def shown(fig: Figure) -> Figure:
    """``fig``, drawn as a PNG when a notebook cell returns it. Our figures are made
    without pyplot (no backend, safe in scripts and threads), and IPython shows such a
    Figure only as its repr; IPython looks ``_repr_png_`` up on the object itself."""

    def png() -> bytes:
        buffer = io.BytesIO()
        fig.savefig(buffer, format="png", dpi=100)
        return buffer.getvalue()

    fig._repr_png_ = png  # type: ignore[attr-defined]
    return fig


@dataclass(frozen=True, repr=False)
class Curve:
    """The response of one design along its indentation sweep, as numpy arrays.

    Attributes
    ----------
    delta : ndarray, shape (K,)
        Global indentation Delta [units of R], from 0 to Delta_max.
    p_star : ndarray, shape (K,)
        Dimensionless pressure P* = P / E*.
    alpha : ndarray, shape (K,)
        Contact-area fraction A_real / A_nom.
    stiffness : ndarray, shape (K,)
        S* = dP*/dalpha.
    model : str
        The forward model's label.
    notes : tuple of str
        What the user should know about the result (asperities that never touch).
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
    resolve_engagement: bool = False,
    device: torch.device | None = None,
) -> Curve:
    """The :class:`Curve` of a design under a forward model (float64, no gradients).

    resolve_engagement: add Delta samples clustered geometrically just after each asperity
    touches (Delta = h_i), where S* dips towards 0 over a tiny range of Delta that a uniform
    sweep samples at random depths (for figures: S* then draws as clean cusps, not spikes).
    device: where the sweep runs (default the CPU); the curve is numpy.
    """
    m = get_model(model)
    dev = device or torch.device("cpu")
    with torch.no_grad():
        if resolve_engagement:
            delta = torch.as_tensor(_engagement_grid(design, steps), device=dev)
            sw = m.sweep(
                torch.as_tensor(design.gamma, device=dev)[None],
                torch.as_tensor(design.h, device=dev)[None],
                design.settings,
                smooth=smooth,
                delta=delta,
            )
        elif dev.type == "cpu":
            sw = m.design_sweep(design, n_delta=steps, smooth=smooth)
        else:  # design_sweep's tensors, on the device
            gamma, h = (t.to(dev) for t in design.tensors(torch.float64))
            sw = m.sweep(gamma, h, design.settings, smooth=smooth, n_delta=steps)
    delta = sw.delta if sw.delta.dim() == 1 else sw.delta[0]
    for name in ("p_star", "alpha", "stiffness"):
        if not torch.isfinite(getattr(sw, name)[0]).all():
            raise MetainterfaceError(
                f"the {m.label} model gives a non-finite {name} for this design"
                + (f" with smooth = {smooth:g}" if smooth is not None else "")
                + "; the curve would be wrong, so none is returned"
            )
    return Curve(
        delta=delta.cpu().numpy().copy(),
        p_star=sw.p_star[0].cpu().numpy().copy(),
        alpha=sw.alpha[0].cpu().numpy().copy(),
        stiffness=sw.stiffness[0].cpu().numpy().copy(),
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


def reach_counts(
    design: Design,
    model: str | ForwardModel | None = None,
    target: tuple[np.ndarray, np.ndarray] | None = None,
) -> tuple[float, tuple[int, ...]]:
    """(coverage, idle) of a design against a target's (p_star, alpha), under a model.

    coverage: the fraction of the target's load range the design reaches
    (:func:`~metainterface.physics.metrics.coverage`; 1.0 without a target). idle: indices
    of the asperities that carry no load, never touching within Delta_max or, with a
    target, only past its largest load (:func:`~metainterface.physics.curves.idle_mask`).
    """
    from metainterface.physics.curves import idle_mask
    from metainterface.physics.metrics import coverage

    m = get_model(model)
    gamma, h = design.tensors(torch.float64)
    s = design.settings
    with torch.no_grad():
        ends = torch.tensor([[0.0, s.delta_max]], dtype=torch.float64)
        p_max = m.sweep(gamma, h, s, delta=ends).p_star[:, -1]
        if target is None:
            return 1.0, tuple(int(i) for i in np.flatnonzero(design.idle))
        p_t = torch.as_tensor(np.asarray(target[0], dtype=np.float64))[None]
        cov = float(coverage(p_t, p_max)[0])
        idle = idle_mask(gamma, h, s, p_t[:, -1], sweep_fn=m.sweep)[0].numpy()
    return cov, tuple(int(i) for i in np.flatnonzero(idle))


def reach_note(coverage: float, idle: tuple[int, ...], n: int) -> tuple[str, ...]:
    """What a user must know about a design that stops short or has idle asperities."""
    out = []
    if coverage < 0.999:
        out.append(
            f"the design reaches only {100 * coverage:.3g} % of the target's load range; "
            "the error charges the rest (coverage)"
        )
    if idle:
        out.append(
            f"{len(idle)} of {n} asperities (index {', '.join(map(str, idle))}) carry no load "
            "within Delta_max and the target's load range"
        )
    return tuple(out)


def _engagement_grid(design: Design, steps: int) -> np.ndarray:
    """(K,) sorted Delta in [0, Delta_max]: ``steps`` uniform ones plus 24 per asperity,
    geometric from 1e-7 to 0.05 Delta_max after its engagement."""
    d_max = design.settings.delta_max
    h = design.h - design.h.min()
    after = h[:, None] + d_max * np.geomspace(1e-7, 5e-2, 24)[None, :]
    grid = np.concatenate([np.linspace(0.0, d_max, steps), h, after.ravel()])
    return np.unique(grid[(grid >= 0) & (grid <= d_max)])


def decimate(n: int, most: int = RECORD_POINTS) -> np.ndarray:
    """Indices of at most ``most`` of ``n`` points, evenly spread, first and last kept."""
    if n <= most:
        return np.arange(n)
    return np.unique(np.linspace(0, n - 1, most).round().astype(int))


class ReachCounts:
    """``coverage``, ``idle`` and ``carrying`` of a result's design (:func:`reach_counts`),
    computed once; a result class names its forward model and reference curve in
    ``_reach_of``."""

    design: Design

    def _reach_of(self) -> tuple[ForwardModel | None, tuple[np.ndarray, np.ndarray] | None]:
        raise NotImplementedError

    @functools.cached_property
    def _reach(self) -> tuple[float, tuple[int, ...]]:
        return reach_counts(self.design, *self._reach_of())

    @property
    def coverage(self) -> float:
        """The fraction of the target's load range (0 to its largest P*) the design reaches."""
        return self._reach[0]

    @property
    def idle(self) -> tuple[int, ...]:
        """Indices of the asperities that carry no load (never touch within Delta_max, or
        only past the target's largest load)."""
        return self._reach[1]

    @property
    def carrying(self) -> int:
        """The number of load-carrying asperities, N - len(idle)."""
        return self.design.n_asperities - len(self.idle)
