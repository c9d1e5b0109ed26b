"""alpha(P*) and S*(P*) of one design."""

from __future__ import annotations

from matplotlib.axes import Axes
from matplotlib.figure import Figure

from metainterface.plots.common import panel_grid, short, tidy_axis


def plot_curve(curve, *, title: str | None = None, width: float = 9.0) -> Figure:
    """Two panels: contact-area fraction and stiffness against P* of one curve (numpy
    p_star, alpha, stiffness (K,), e.g. ``metainterface.curve(design)``).

    title: a name for the figure (a path is cut to its file name); width: inches."""
    fig, (ax_a, ax_s) = panel_grid(2, width, aspect=0.75)
    p = curve.p_star
    ax_a.plot(p, curve.alpha, color="k")
    ax_a.set(xlabel="P* = P / E*", ylabel="α = A / Aₙₒₘ", title="contact area")
    touching = curve.alpha > 0  # S* is 0 by convention before the first contact
    ax_s.plot(p[touching], curve.stiffness[touching], color="C0")
    ax_s.set(xlabel="P*", ylabel="S* = dP* / dα", title="stiffness")
    for ax in (ax_a, ax_s):
        ax.grid(alpha=0.3)
        ax.set_xlim(0, 1.02 * float(p[-1]))
        ax.set_ylim(bottom=0)
        tidy_axis(ax)
    if title:
        fig.suptitle(short(title), fontsize=10)
    return fig


def draw_curve(ax: Axes, curve, *, label: str | None = None, target=None) -> Axes:
    """alpha(P*) of a curve on an existing axes (and a target's, if given); returns it."""
    top = float(curve.p_star[-1])
    if target is not None:
        ax.plot(target.p_star, target.alpha, "k-", lw=2, label=f"target {short(target.name)}")
        top = max(top, target.p_star_max)
    ax.plot(curve.p_star, curve.alpha, "--" if target is not None else "-", label=label)
    ax.set(xlabel="P* = P / E*", ylabel="α = A / Aₙₒₘ")
    ax.set_xlim(0, 1.03 * top)
    ax.set_ylim(bottom=0)
    ax.grid(alpha=0.3)
    tidy_axis(ax)
    if label or target is not None:
        ax.legend(fontsize=8)
    return ax
