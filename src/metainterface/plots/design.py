"""The design figure (target vs achieved, parameters, top view) and the method comparison."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import torch
from matplotlib.figure import Figure

from metainterface.plots.common import new_figure

COLORS = {"surrogate": "C0", "multistart": "C2", "hertz": "C1"}


def plot_design(result, curve) -> Figure:
    """alpha(P*) and S*(P*) target vs design; gamma and h per asperity; top view of the cell.

    result: a DesignResult (target, design, error); curve: the design's curve (numpy
    p_star, alpha, stiffness (K,)), e.g. ``result.curve()``.
    """
    fig = new_figure(13.0, 3.6)
    ax_a, ax_s, ax_p, ax_top = fig.subplots(1, 4)
    t = result.target
    p, a, s = curve.p_star, curve.alpha, curve.stiffness
    design = result.design
    ax_a.plot(t.p_star, t.alpha, "k-", lw=2, label="target")
    ax_a.plot(p, a, "--", color="C0", label=f"design ({100 * result.error:.2f} %)")
    ax_a.set(xlabel="$P^*$", ylabel=r"$\alpha$", title=f"{t.name}: contact area")
    ax_a.legend(fontsize=8)
    if t.stiffness is not None:
        ax_s.plot(t.p_star, t.stiffness, "k-", lw=2, label="target")
    ax_s.plot(p, s, "--", color="C0", label="design")
    ax_s.set(xlabel="$P^*$", ylabel="$S^* = dP^*/d\\alpha$", title="stiffness")
    ax_s.set_xlim(0, t.p_star_max * 1.05)
    k = np.arange(design.gamma.size)
    ax_p.bar(k - 0.2, design.gamma, 0.4, color="C0", label=r"$\gamma$")
    ax_h = ax_p.twinx()
    ax_h.bar(
        k + 0.2, design.h / design.settings.delta_max, 0.4, color="C3", label=r"$h/\Delta_{max}$"
    )
    ax_p.set(xlabel="asperity k", ylabel=r"$\gamma$", title="parameters")
    ax_h.set_ylabel(r"$h/\Delta_{max}$", color="C3")
    _top_view(ax_top, design)
    for ax in (ax_a, ax_s):
        ax.grid(alpha=0.3)
    return fig


def _top_view(ax, design) -> None:
    """Each asperity as a disc of its contact radius at Delta_max, shaded by gamma."""
    from matplotlib.patches import Circle, Rectangle

    from metainterface.physics.sneddon import contact_radius

    st = design.settings
    centres = st.lattice_centres()
    delta = torch.as_tensor(np.maximum(st.delta_max - (design.h - design.h.min()), 0.0))
    a = contact_radius(torch.as_tensor(design.gamma), delta, st.radius).numpy()
    pitch = st.cell_side / st.n_side
    for (x, y), g, r, hh in zip(centres, design.gamma, a, design.h, strict=True):
        ax.add_patch(Rectangle((x - pitch / 2, y - pitch / 2), pitch, pitch, fill=False, lw=0.5))
        shade = (g - st.gamma_min) / (st.gamma_max - st.gamma_min)
        ax.add_patch(Circle((x, y), max(r, 1e-3), color=(0.2, 0.3 + 0.5 * shade, 0.8)))
        ax.text(
            x, y - pitch * 0.4, f"γ={g:.2f}\nh={hh / st.delta_max:.2f}Δ", ha="center", fontsize=6
        )
    ax.set(
        xlim=(0, st.cell_side),
        ylim=(0, st.cell_side),
        aspect="equal",
        title="cell (contact discs at $\\Delta_{max}$)",
        xlabel="x / R",
        ylabel="y / R",
    )


def plot_comparison(results: Sequence[Sequence], curves: Sequence[Sequence]) -> Figure:
    """Paper fig. 5: per target (column), the target and each method's design.

    results[i][j]: target i's DesignResult by method j; curves[i][j]: its curve (numpy
    p_star, alpha)."""
    fig = new_figure(4.2 * len(results), 3.6)
    axes = np.atleast_1d(fig.subplots(1, len(results)))
    for ax, per_method, per_curve in zip(axes, results, curves, strict=True):
        t = per_method[0].target
        ax.plot(t.p_star, t.alpha, "k-", lw=2.5, label="target")
        for r, c in zip(per_method, per_curve, strict=True):
            ax.plot(
                c.p_star,
                c.alpha,
                "--",
                color=COLORS.get(r.method, "C4"),
                label=f"{r.method}: {100 * r.error:.2f} %, {r.seconds:.2f} s",
            )
        ax.set(xlabel="$P^*$", ylabel=r"$\alpha$", title=t.name, xlim=(0, t.p_star_max * 1.05))
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7)
    return fig
