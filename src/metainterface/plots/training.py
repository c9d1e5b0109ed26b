"""The training panels of the paper's fig. 4 (a-d)."""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from metainterface.plots.common import new_figure


def plot_training(metrics: dict[str, np.ndarray]) -> Figure:
    """(a) train/validation loss, (b) kappa_s, (c) lambda, (d) learning rate, against epoch."""
    fig = new_figure(10.0, 6.5)
    axes = fig.subplots(2, 2)
    ep = metrics["epoch"]
    ax = axes[0, 0]
    ax.plot(ep, metrics["train_loss"], label="train (current $\\kappa_s$)")
    ax.plot(ep, metrics["val_loss"], label="validation (exact contact)")
    ax.set(yscale="log", xlabel="epoch", ylabel="loss", title="(a) loss")
    ax.legend()
    panels = [
        (axes[0, 1], "kappa", "$\\kappa_s$", "(b) contact regularisation", "log"),
        (axes[1, 0], "lambda", "$\\lambda$", "(c) curriculum weight", "linear"),
        (axes[1, 1], "lr", "learning rate", "(d) cosine annealing", "linear"),
    ]
    for ax, key, label, title, scale in panels:
        ax.plot(ep, metrics[key], color="k")
        ax.set(yscale=scale, xlabel="epoch", ylabel=label, title=title)
    for ax in axes.flat:
        ax.grid(alpha=0.3)
    return fig
