"""The paper's fig. 3: test curves (solid black) and the surrogate's zero-shot designs
(dashed blue), a few per topography category."""

from __future__ import annotations

import numpy as np
import torch
from matplotlib.figure import Figure

from metainterface.physics.cell import CellSettings
from metainterface.physics.curves import sweep
from metainterface.plots.common import panel_grid, percent, tidy_axis

ORDER = ("lhs", "mixed", "truncated", "bimodal", "coplanar", "stratified")


def plot_reconstructions(
    test, pred, settings: CellSettings, per_category: int = 3, *, width: float = 12.0
) -> Figure:
    """test: the dataset's test subset; pred: :class:`Predictions` of the same rows.
    width: inches (three panels per row when they fit)."""
    fig, axes = panel_grid(6, width, max_cols=3, min_panel=3.4, aspect=0.85)
    p_hat = np.linspace(0, 1, settings.n_steps)
    for ax, (letter, name) in zip(axes, zip("abcdef", ORDER, strict=True), strict=True):
        rows = np.flatnonzero(test.category == name)
        if rows.size == 0:
            ax.set_title(f"({letter}) {name}: no test samples")
            continue
        pick = rows[np.linspace(0, rows.size - 1, min(per_category, rows.size)).astype(int)]
        for j, i in enumerate(pick):
            color = f"C{j}"
            ax.plot(p_hat * test.p_star_max[i], test.alpha_hat[i] * test.alpha_max[i], "k-", lw=1.8)
            sw = sweep(
                torch.as_tensor(pred.gamma[i : i + 1]),
                torch.as_tensor(pred.h[i : i + 1]),
                settings,
                n_delta=256,
            )
            ax.plot(
                sw.p_star[0],
                sw.alpha[0],
                "--",
                color=color,
                lw=1.4,
                label=f"err {percent(pred.curve_error[i])}",
            )
        ax.set(title=f"({letter}) {name}", xlabel="$P^*$", ylabel=r"$\alpha$")
        ax.set_xlim(left=0)
        ax.set_ylim(bottom=0)
        ax.grid(alpha=0.3)
        tidy_axis(ax, bins=4)
        ax.legend(fontsize=7, title="true (black) / predicted", title_fontsize=7)
    return fig
