"""BEM validation of one design, like the paper's fig. 6: curves, topography, pressure."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np
from matplotlib.figure import Figure

from metainterface.plots.common import panel_grid, percent, short, tidy_axis

if TYPE_CHECKING:
    from metainterface.validation.result import ValidationResult


def plot_validation(
    result: ValidationResult,
    *,
    target: tuple[np.ndarray, np.ndarray] | None = None,
    title: str | None = None,
    width: float = 13.0,
    fields: Any = None,
) -> Figure:
    """Three panels: alpha(P*) (target, model, BEM), the cell's height map, p/E* at the
    largest load. target: optional (p_star, alpha) arrays of the design's target curve.
    title: a name (a path is cut to its file name); width: inches.
    fields: the result's fields file as an xarray Dataset (``metainterface.io.fields``):
    the pressure panel then shows what the file holds, in its coordinates and units."""
    fig, (ax_c, ax_h, ax_p) = panel_grid(3, width, min_panel=3.6, aspect=0.82)
    p_top = float(result.p_star[-1])
    keep = result.curve.p_star <= p_top * (1 + 1e-12)
    if target is not None:
        ax_c.plot(target[0], target[1], color="k", lw=1.5, label="target")
    ax_c.plot(
        result.curve.p_star[keep],
        result.curve.alpha[keep],
        ls="--",
        color="C0",
        label=f"model ({result.model.label})",
    )
    ax_c.plot(
        result.p_star,
        result.alpha_bem,
        "o",
        mfc="none",
        color="C3",
        label=f"BEM ({result.grid}²)",
    )
    ax_c.set(xlabel="P* = P / E*", ylabel="α = A / Aₙₒₘ", title="contact area")
    ax_c.set_xlim(left=0)
    ax_c.set_ylim(bottom=0)
    ax_c.grid(alpha=0.3)
    tidy_axis(ax_c)
    ax_c.legend(
        fontsize=8,
        loc="lower right",
        title=f"max |rel. err.|, upper half: {percent(result.max_rel_err_upper)}",
        title_fontsize=8,
    )

    radius = result.design.settings.radius  # axes in units of R
    side = result.heights.cell_side / radius
    extent = (0.0, side, 0.0, side)
    # Colours span the heights that can touch (a few Delta_max below the highest tip); the
    # deep cell corners saturate.
    z = result.heights.heights / radius
    z_low = max(float(z.min()), -4.0 * result.design.settings.delta_max / radius)
    im = ax_h.imshow(z, origin="lower", extent=extent, cmap="viridis", vmin=z_low, vmax=0.0)
    ax_h.set(xlabel="x / R", ylabel="y / R", title="topography")
    fig.colorbar(im, ax=ax_h, label="z / R", shrink=0.85, extend="min")
    tidy_axis(ax_h, bins=4)

    pressure, labels = result.pressure, ("x / R", "y / R")
    if fields is not None:
        last = fields["pressure"].isel(load=-1)
        pressure, p_top = np.asarray(last.values), float(last["p_star"])
        units = fields["x"].attrs.get("units", "R")
        scale = 1e3 if units == "m" else 1.0  # metres are drawn in mm
        x, y = scale * np.asarray(fields["x"].values), scale * np.asarray(fields["y"].values)
        step = x[1] - x[0]  # pixel edges: the cell is periodic, grid point i at i * step
        extent = (float(x[0]), float(x[-1] + step), float(y[0]), float(y[-1] + step))
        labels = ("x / R", "y / R") if units == "R" else ("x [mm]", "y [mm]")
    im = ax_p.imshow(pressure, origin="lower", extent=extent, cmap="magma")
    ax_p.set(xlabel=labels[0], ylabel=labels[1], title=f"p / E* at P* = {p_top:.3g}")
    fig.colorbar(im, ax=ax_p, label="p / E*", shrink=0.85)
    tidy_axis(ax_p, bins=4)
    if title:
        fig.suptitle(short(title), fontsize=10)
    return fig
