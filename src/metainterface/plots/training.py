"""The training panels of the paper's fig. 4 (a-d)."""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from metainterface.plots.common import panel_grid, tidy_axis

#: Up to this many epochs each one is drawn as a point too (one epoch is a point, not an
#: invisible line of length zero).
MARKED_EPOCHS = 40


def plot_training(metrics: dict[str, np.ndarray], *, width: float = 10.0) -> Figure:
    """(a) train/validation loss, (b) kappa_s, (c) lambda, (d) learning rate, against epoch.

    metrics: arrays (E,) 'epoch', 'train_loss', 'val_loss', 'kappa', 'lambda', 'lr' (the
    run's metrics.csv). width: inches."""
    fig, axes = panel_grid(4, width, max_cols=2, aspect=0.62)
    ep = np.asarray(metrics["epoch"])
    mark = {"marker": "o", "ms": 4} if ep.size <= MARKED_EPOCHS else {}
    ax = axes[0]
    ax.plot(ep, metrics["train_loss"], label="train (current $\\kappa_s$)", **mark)
    ax.plot(ep, metrics["val_loss"], label="validation (exact contact)", **mark)
    ax.set(yscale="log", xlabel="epoch", ylabel="loss", title="(a) loss")
    ax.legend(fontsize=8)
    panels = [
        (axes[1], "kappa", "$\\kappa_s$", "(b) contact regularisation", "log"),
        (axes[2], "lambda", "$\\lambda$", "(c) curriculum weight", "linear"),
        (axes[3], "lr", "learning rate", "(d) cosine annealing", "linear"),
    ]
    for ax, key, label, title, scale in panels:
        ax.plot(ep, metrics[key], color="k", **mark)
        ax.set(yscale=scale, xlabel="epoch", ylabel=label, title=title)
    for ax in axes:
        ax.grid(alpha=0.3)
        if ep.size <= 1:  # one epoch: a window around it, whole-number ticks
            ax.set_xlim(float(ep[0]) - 1, float(ep[0]) + 1)
        ax.xaxis.get_major_locator().set_params(integer=True)
        tidy_axis(ax, x=False)
    return fig
