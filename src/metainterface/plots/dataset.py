"""Example alpha(P*) curves of the dataset's categories (like the solid lines of paper fig. 3)."""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np
from matplotlib.figure import Figure

from metainterface.errors import MetainterfaceError
from metainterface.plots.common import panel_grid, short, tidy_axis


def plot_dataset_examples(
    examples: Mapping[str, Mapping[str, np.ndarray]],
    *,
    title: str | None = None,
    width: float | None = None,
) -> Figure:
    """One panel per entry of ``examples`` (in its order): alpha against P* of a few samples.

    examples: panel title -> arrays of k samples: p_star_max (k,), alpha_max (k,) and
        alpha_hat (k, n) on the uniform grid P / P*_max in [0, 1] (the dataset's arrays).
    Curves are drawn de-normalised, alpha = alpha_hat alpha_max against P* = P_hat P*_max,
    as solid black lines (shades of grey tell the samples apart). width: inches (default
    3.4 per panel, three per row).
    """
    panels = list(examples.items())
    if not panels:
        raise MetainterfaceError("plot_dataset_examples: give at least one category")
    width = 3.4 * min(3, len(panels)) if width is None else width
    fig, axes = panel_grid(len(panels), width, max_cols=3, aspect=0.85)
    for ax, (name, arrays) in zip(axes, panels, strict=True):
        alpha_hat = np.asarray(arrays["alpha_hat"], dtype=np.float64)
        p_max = np.asarray(arrays["p_star_max"], dtype=np.float64)
        a_max = np.asarray(arrays["alpha_max"], dtype=np.float64)
        p_hat = np.linspace(0.0, 1.0, alpha_hat.shape[-1])
        k = alpha_hat.shape[0]
        for i in range(k):
            shade = str(0.55 * i / max(1, k - 1))
            ax.plot(p_hat * p_max[i], alpha_hat[i] * a_max[i], color=shade, lw=1.2)
        ax.set_title(short(name, 28), fontsize=9)
        ax.set_xlabel(r"$P^* = P/E^*$")
        ax.set_ylabel(r"$\alpha = A/A_{nom}$")
        ax.set_xlim(left=0)
        ax.set_ylim(bottom=0)
        ax.grid(alpha=0.3)
        tidy_axis(ax, bins=4)
    if title:
        fig.suptitle(short(title), fontsize=10)
    return fig
