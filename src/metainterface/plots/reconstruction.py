"""The paper's fig. 3: test curves (solid black) and the surrogate's zero-shot designs
(dashed blue), a few per topography category."""

from __future__ import annotations

import numpy as np
import torch
from matplotlib.figure import Figure
from matplotlib.ticker import MaxNLocator

from metainterface.physics.cell import CellSettings
from metainterface.physics.curves import sweep
from metainterface.plots.common import new_figure

ORDER = ("lhs", "mixed", "truncated", "bimodal", "coplanar", "stratified")


def plot_reconstructions(test, pred, settings: CellSettings, per_category: int = 3) -> Figure:
    """test: the dataset's test subset; pred: :class:`Predictions` of the same rows."""
    fig = new_figure(12.0, 7.0)
    axes = fig.subplots(2, 3).ravel()
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
                label=f"err {100 * pred.curve_error[i]:.1f} %",
            )
        ax.set(title=f"({letter}) {name}", xlabel="$P^*$", ylabel=r"$\alpha$")
        ax.xaxis.set_major_locator(MaxNLocator(4))
        ax.ticklabel_format(axis="x", style="sci", scilimits=(-2, 2))
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7, title="true (black) / predicted", title_fontsize=7)
    return fig
