"""The measured part in one figure: scan, designed map, difference, predicted law."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from matplotlib.figure import Figure


def measure_figure(
    *,
    scan: np.ndarray,
    designed: np.ndarray,
    extent: tuple[float, float, float, float],
    p_star: np.ndarray,
    alpha_bem: np.ndarray,
    alpha_fit: np.ndarray,
    target: tuple[np.ndarray, np.ndarray],
    error_bem: float,
    error_design: float,
    orientation: str | None = None,
    lattice: tuple[np.ndarray, np.ndarray] | None = None,
    to_forces: Callable[[np.ndarray, np.ndarray], tuple[np.ndarray, np.ndarray]] | None = None,
) -> Figure:
    """Four panels. scan, designed: (ny, nx) levelled heights [um] on the scan's grid;
    extent: (x0, x1, y0, y1) [um]; p_star, alpha_bem, alpha_fit: (K,); target: (p, alpha).
    orientation: the orientation found, in words (the scan panel's title); lattice: the
    design's cell axes in the scan, ((2,) origin, (2, 2) u and v ends) [um], drawn as arrows
    on the scan. to_forces: (p_star, alpha) -> (normal force, friction) [N]; with it the
    law is drawn as friction against normal force."""
    fig = Figure(figsize=(13, 3.6), layout="constrained")
    axes = fig.subplots(1, 4)
    lo, hi = np.nanpercentile(designed, [1, 100])
    for ax, data, title in (
        (axes[0], scan, "scan, levelled [um]"),
        (axes[1], designed, "designed, registered [um]"),
    ):
        im = ax.imshow(data, origin="lower", extent=extent, vmin=lo, vmax=hi, cmap="viridis")
        ax.set_title(title, fontsize=9)
        ax.set_xlabel("x [um]")
        fig.colorbar(im, ax=ax, shrink=0.8)
    if orientation is not None:
        axes[0].set_title(f"scan, levelled [um]\n{orientation}", fontsize=9)
    if lattice is not None:  # the design's u (white) and v (red) axes where they lie
        o, ends = lattice
        for end, colour, name in ((ends[0], "w", "u"), (ends[1], "r", "v")):
            axes[0].annotate(
                "", xy=end, xytext=o, arrowprops={"arrowstyle": "->", "color": colour, "lw": 1.5}
            )
            axes[0].annotate(
                name,
                xy=end,
                xytext=(3, 3),
                textcoords="offset points",
                color=colour,
                fontsize=10,
                fontweight="bold",
            )
    diff = scan - designed
    lim = float(np.nanpercentile(np.abs(diff), 99)) or 1.0
    im = axes[2].imshow(diff, origin="lower", extent=extent, vmin=-lim, vmax=lim, cmap="RdBu_r")
    axes[2].set_title("made - designed [um]")
    axes[2].set_xlabel("x [um]")
    fig.colorbar(im, ax=axes[2], shrink=0.8)
    ax = axes[3]

    def law(p: np.ndarray, a: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        return (p, a) if to_forces is None else to_forces(p, a)

    ax.plot(*law(*target), "k-", lw=1.5, label=f"target (design {100 * error_design:.2g} %)")
    ax.plot(*law(p_star, alpha_bem), "o-", color="C3", label=f"made, BEM ({100 * error_bem:.2g} %)")
    ax.plot(*law(p_star, alpha_fit), "s--", color="C0", ms=4, label="made, fitted model")
    if to_forces is None:
        ax.set_xlabel("P* = P / E*")
        ax.set_ylabel("alpha = A_real / A_nom")
    else:
        ax.set_xlabel("normal force [N]")
        ax.set_ylabel("friction force [N]")
    ax.set_title("predicted law")
    ax.ticklabel_format(axis="x", style="sci", scilimits=(-2, 2))
    ax.legend(fontsize=8)
    return fig
