"""alpha(P*) and S*(P*) of one design."""

from __future__ import annotations

from matplotlib.axes import Axes
from matplotlib.figure import Figure

from metainterface.plots.common import new_figure


def plot_curve(curve, *, title: str | None = None) -> Figure:
    """Two panels: contact-area fraction and stiffness against P* of one curve (numpy
    p_star, alpha, stiffness (K,), e.g. ``metainterface.curve(design)``)."""
    fig = new_figure()
    ax_a, ax_s = fig.subplots(1, 2)
    p = curve.p_star
    ax_a.plot(p, curve.alpha, color="k")
    ax_a.set(xlabel=r"$P^* = P/E^*$", ylabel=r"$\alpha = A/A_{nom}$", title="contact area")
    ax_s.plot(p, curve.stiffness, color="C0")
    ax_s.set(xlabel=r"$P^*$", ylabel=r"$S^* = dP^*/d\alpha$", title="stiffness")
    for ax in (ax_a, ax_s):
        ax.grid(alpha=0.3)
        ax.set_xlim(left=0)
        ax.set_ylim(bottom=0)
    if title:
        fig.suptitle(title, fontsize=9)
    return fig


def draw_curve(ax: Axes, curve, *, label: str | None = None, target=None) -> Axes:
    """alpha(P*) of a curve on an existing axes (and a target's, if given); returns it."""
    if target is not None:
        ax.plot(target.p_star, target.alpha, "k-", lw=2, label=f"target {target.name}")
    ax.plot(curve.p_star, curve.alpha, "--" if target is not None else "-", label=label)
    ax.set(xlabel=r"$P^* = P/E^*$", ylabel=r"$\alpha = A/A_{nom}$")
    ax.set_xlim(left=0)
    ax.set_ylim(bottom=0)
    ax.grid(alpha=0.3)
    if label or target is not None:
        ax.legend(fontsize=8)
    return ax
