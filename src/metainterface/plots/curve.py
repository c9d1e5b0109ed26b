"""alpha(P*) and S*(P*) of one design."""

from __future__ import annotations

from matplotlib.figure import Figure

from metainterface.physics.curves import Sweep
from metainterface.plots.common import new_figure


def plot_curve(sw: Sweep, *, index: int = 0, title: str | None = None) -> Figure:
    """Two panels: contact-area fraction and stiffness against P*, for design ``index``."""
    fig = new_figure()
    ax_a, ax_s = fig.subplots(1, 2)
    p = sw.p_star[index].detach().cpu().numpy()
    ax_a.plot(p, sw.alpha[index].detach().cpu().numpy(), color="k")
    ax_a.set(xlabel=r"$P^* = P/E^*$", ylabel=r"$\alpha = A/A_{nom}$", title="contact area")
    ax_s.plot(p, sw.stiffness[index].detach().cpu().numpy(), color="C0")
    ax_s.set(xlabel=r"$P^*$", ylabel=r"$S^* = dP^*/d\alpha$", title="stiffness")
    for ax in (ax_a, ax_s):
        ax.grid(alpha=0.3)
        ax.set_xlim(left=0)
        ax.set_ylim(bottom=0)
    if title:
        fig.suptitle(title, fontsize=9)
    return fig
