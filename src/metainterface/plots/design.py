"""The design figure (target vs achieved, in P* and, for a friction law, in newtons; the
parameters; the cell's topography) and the method comparison.

Labels are plain Unicode text (α, γ, Δmax, P*), not mathtext: the first mathtext label of a
process builds matplotlib's parser, and that and the parses were 0.3-0.8 s of every
``metainterface design`` run."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import torch
from matplotlib.figure import Figure
from matplotlib.patches import Patch

from metainterface.plots.common import new_figure, panel_grid, percent, short, tidy_axis

COLORS = {"surrogate": "C0", "multistart": "C2", "hertz": "C1"}
#: Most target points drawn (a 100,000-row target draws as fast as a 100-row one).
DRAW_POINTS = 512


def _every(n: int, most: int = DRAW_POINTS) -> np.ndarray:
    return np.unique(np.linspace(0, n - 1, min(n, most)).round().astype(int))


def target_stiffness(target) -> np.ndarray:
    """S* = dP*/dalpha of a target: its own when it has one, else central differences over
    (at most ``DRAW_POINTS``) of its points; NaN where alpha does not grow."""
    keep = _every(target.p_star.size)
    if target.stiffness is not None:
        return target.stiffness[keep]
    p, a = target.p_star[keep], target.alpha[keep]
    if p.size < 3:
        return np.full(p.size, np.nan)
    with np.errstate(divide="ignore", invalid="ignore"):
        s = np.gradient(p, a)
    s[~np.isfinite(s) | (s < 0)] = np.nan
    return s


def friction_units(meta: dict) -> dict | None:
    """tau, E* [Pa], the nominal area [m^2] and the law's forces [N] of a target made from a
    friction law, from its ``meta`` (or design.json's "target" entry); None otherwise."""
    law = meta.get("friction") if isinstance(meta, dict) else None
    if not isinstance(law, dict):
        return None
    try:
        return {
            "tau": float(law["shear_strength_pa"]),
            "e_star": float(law["e_star_pa"]),
            "area": float(law["area_m2"]),
            "normal": np.asarray(law.get("normal_force_n", []), dtype=np.float64),
            "friction": np.asarray(law.get("friction_force_n", []), dtype=np.float64),
        }
    except (KeyError, TypeError, ValueError):
        return None


def _force_unit(top: float) -> tuple[float, str]:
    """(scale, unit) that shows forces up to ``top`` newtons as numbers of order 1-1000."""
    for scale, unit in ((1e3, "kN"), (1.0, "N"), (1e-3, "mN"), (1e-6, "µN")):
        if top >= scale:
            return scale, unit
    return 1e-9, "nN"


def plot_design(result, curve, *, width: float | None = None) -> Figure:
    """The design against its target: alpha(P*) and S*(P*) on one pressure range; for a
    target made from a friction law, the friction force and coefficient against the normal
    force in newtons; gamma and h per asperity; the cell's topography.

    result: a DesignResult (target, design, error); curve: the design's curve (numpy
    p_star, alpha, stiffness (K,)), e.g. ``result.figure_curve()``. width: inches
    (default 12; the height follows).
    """
    width = 12.0 if width is None else float(width)
    t = result.target
    units = friction_units(t.meta)
    # Panels per row from the width (about 2.8 inches each at least), so a narrow figure
    # stacks them instead of squeezing their labels together.
    panels = 6 if units else 4
    cols = 4 if (units and width >= 11) else 2 if width >= 5 else 1
    if not units and width >= 11:
        cols = 2
    rows = 2 if cols == 4 else -(-panels // cols)
    row_height = width / cols * (0.78 if cols > 1 else 0.72)
    fig = new_figure(width, row_height * rows * (1.1 if cols == 4 else 1.0))
    ratios = (1.0, 1.25) if cols == 4 else (1.0,) * rows
    grid = fig.add_gridspec(rows, cols, height_ratios=ratios)
    if cols == 4:
        spots = [grid[0, 0], grid[0, 1], grid[0, 2], grid[0, 3], grid[1, :2], grid[1, 2:]]
    else:
        spots = [grid[i // cols, i % cols] for i in range(panels)]
    ax_a = fig.add_subplot(spots[0])
    ax_s = fig.add_subplot(spots[1], sharex=ax_a)
    if units:
        ax_f = fig.add_subplot(spots[2])
        ax_m = fig.add_subplot(spots[3], sharex=ax_f)
    ax_p = fig.add_subplot(spots[-2])
    ax_c = fig.add_subplot(spots[-1])
    what = f"{result.method} design, error {percent(result.error)}"
    coverage = getattr(result, "coverage", 1.0)
    if coverage < 0.999:
        what += f", coverage {percent(coverage)}"
    if getattr(result, "bem", None) is not None:
        what += f", BEM {percent(result.bem.bem_error)}"
    name = short(t.name, max(16, min(40, int(5 * width))))
    one_line = len(name) + len(what) + 2 <= min(60, 9 * width)
    title = f"{name}: {what}" if one_line else f"{name}\n{what}"
    if getattr(result, "forced", False):
        title += "\nFORCED: the law is out of reach; the closest cell"
    fig.suptitle(title, fontsize=11)

    keep = _every(t.p_star.size)
    p_top = 1.03 * max(t.p_star_max, float(curve.p_star[-1]))
    ax_a.plot(t.p_star[keep], t.alpha[keep], "k-", lw=2, label="target")
    ax_a.plot(curve.p_star, curve.alpha, "--", color="C0", label="design")
    p_stop = float(curve.p_star[-1])
    stops = p_stop < 0.999 * t.p_star_max  # the design ends inside the target's range
    if stops:
        for ax in (ax_a, ax_s):
            ax.axvline(p_stop, color="C3", ls=":", lw=1.2, label="design stops")
    bem = getattr(result, "bem", None)
    if bem is not None:  # the design solved in BEM at the check's loads
        ax_a.plot(
            bem.p_star,
            bem.alpha_bem,
            "o",
            color="C3",
            ms=4,
            label=f"BEM {bem.grid}²: {percent(bem.bem_error)}",
        )
    ax_a.set(xlabel="P* = P / E*", ylabel="α = A / Aₙₒₘ", title="contact area")
    ax_a.set_xlim(0, p_top)
    ax_a.set_ylim(bottom=0)
    ax_a.legend(fontsize=8, loc="lower right")

    s_t = target_stiffness(t)
    if np.isfinite(s_t).any():
        how = "target" if t.stiffness is not None else "target (differences)"
        ax_s.plot(t.p_star[keep], s_t, "k-", lw=2, label=how)
    touching = curve.alpha > 0  # S* is 0 by convention before the first contact
    # Solid: S* dips to 0 where a gamma > 2 asperity engages (its area grows infinitely fast
    # at first touch); the dense, engagement-resolved curve draws those as clean cusps.
    ax_s.plot(
        curve.p_star[touching], curve.stiffness[touching], "-", color="C0", lw=1.2, label="design"
    )
    # The target's differences of measured points can spike: its 98th percentile sets the
    # scale, so a noisy point does not flatten both curves.
    finite = s_t[np.isfinite(s_t)]
    s_top = max(float(curve.stiffness.max()), np.percentile(finite, 98) if finite.size else 0.0)
    ax_s.set(xlabel="P*", ylabel="S* = dP* / dα", title="stiffness")
    ax_s.set_ylim(0, 1.08 * s_top if s_top > 0 else 1.0)
    ax_s.legend(fontsize=8, loc="lower right")
    for ax in (ax_a, ax_s):
        ax.grid(alpha=0.3)
        tidy_axis(ax)

    if units:
        _friction_panels(ax_f, ax_m, t, curve, units, stops)
    _parameters(ax_p, result.design)
    idle = getattr(result, "idle", tuple(int(i) for i in result.design.idle))
    labels = _topography(fig, ax_c, result.design, idle)
    _fit_labels(fig, ax_c, labels, result.design.settings.n_side)
    return fig


def _friction_panels(ax_f, ax_m, target, curve, units: dict, stops: bool = False) -> None:
    """Friction force and coefficient against the normal force, in the user's newtons; with
    ``stops``, where the design's load range ends is marked (in the same unit)."""
    tau, e_star, area = units["tau"], units["e_star"], units["area"]
    fn_d, ff_d = curve.p_star * area * e_star, curve.alpha * tau * area
    fn_t = units["normal"] if units["normal"].size else target.p_star * area * e_star
    ff_t = units["friction"] if units["friction"].size else target.alpha * tau * area
    keep = _every(fn_t.size)
    fn_t, ff_t = fn_t[keep], ff_t[keep]
    scale, unit = _force_unit(max(fn_t.max(), fn_d.max(), ff_t.max()))
    style = "ko" if fn_t.size <= 60 else "k-"
    ax_f.plot(fn_t / scale, ff_t / scale, style, ms=4, label="friction law")
    ax_f.plot(fn_d / scale, ff_d / scale, "--", color="C0", label="design")
    ax_f.set(xlabel=f"normal force [{unit}]", ylabel=f"friction force [{unit}]", title="friction")
    ax_f.set_xlim(0, 1.03 * max(fn_t.max(), fn_d.max()) / scale)
    ax_f.set_ylim(bottom=0)
    ax_f.legend(fontsize=8, loc="lower right")
    loaded_t, loaded_d = fn_t > 0, fn_d > 0
    mu_t = ff_t[loaded_t] / fn_t[loaded_t]
    mu_d = ff_d[loaded_d] / fn_d[loaded_d]
    ax_m.plot(fn_t[loaded_t] / scale, mu_t, style, ms=4, label="friction law")
    ax_m.plot(fn_d[loaded_d] / scale, mu_d, "--", color="C0", label="design")
    if stops:
        f_stop = float(fn_d[-1])
        for ax in (ax_f, ax_m):
            ax.axvline(
                f_stop / scale,
                color="C3",
                ls=":",
                lw=1.2,
                label=f"design stops, {f_stop / scale:.3g} {unit}",
            )
    # mu grows without bound as the load goes to 0 (alpha ~ P*^(2/(gamma + 1))): the
    # design's mu is kept in view from a tenth of its load range on, with the law's whole.
    later = fn_d[loaded_d] >= 0.1 * fn_d.max()
    tops = [1.5 * float(mu_t.max())] if mu_t.size else []
    if later.any():
        tops.append(1.15 * float(mu_d[later].max()))
    top = max(tops) if tops else 1.0
    ax_m.set(
        xlabel=f"normal force [{unit}]",
        ylabel="friction coefficient μ",
        title="friction coefficient",
        ylim=(0, top),
    )
    ax_m.legend(fontsize=8, loc="upper right")
    for ax in (ax_f, ax_m):
        ax.grid(alpha=0.3)
        tidy_axis(ax)


def _parameters(ax, design) -> None:
    """gamma and h / Delta_max of each asperity, side by side."""
    k = np.arange(design.gamma.size)
    d_max = design.settings.delta_max
    ax.bar(k - 0.2, design.gamma, 0.4, color="C0")
    ax_h = ax.twinx()
    ax_h.bar(k + 0.2, (design.h - design.h.min()) / d_max, 0.4, color="C3")
    handles = [Patch(color="C0", label="γ"), Patch(color="C3", label="h / Δmax")]
    ax.set(xlabel="asperity k", ylabel="shape exponent γ", title="parameters")
    ax.set_xticks(k if k.size <= 16 else k[:: int(np.ceil(k.size / 16))])
    ax_h.set_ylabel("height offset h / Δmax", color="C3")
    ax.legend(handles=handles, fontsize=8, loc="upper left", ncols=2)
    ax.set_ylim(0, 1.3 * design.gamma.max())  # room for the legend above the bars
    h_top = float((design.h - design.h.min()).max()) / d_max
    ax_h.set_ylim(0, 1.3 * h_top if h_top > 0 else 1.0)


def _topography(fig, ax, design, idle: Sequence[int] = ()) -> list:
    """The cell's height map seen from above (colour bar in units of Delta_max), the contact
    discs at Delta_max outlined, each asperity labelled with k, gamma and h; the ``idle``
    ones (carrying no load) crossed out in red and labelled so."""
    from matplotlib.patches import Circle

    from metainterface.physics.sneddon import contact_radius
    from metainterface.validation.heightmap import height_map

    st = design.settings
    n = st.n_side
    d_max = st.delta_max
    hm = height_map(design, grid=max(96, 32 * n) // n * n)
    z = hm.heights / d_max
    h0 = (design.h - design.h.min()) / d_max
    low = -(float(h0.max()) + 2.0)  # everything that can touch, and a margin below
    side = st.cell_side / st.radius
    im = ax.imshow(
        z,
        origin="lower",
        extent=(0.0, side, 0.0, side),
        cmap="viridis",
        vmin=low,
        vmax=0.0,
        interpolation="nearest",
    )
    fig.colorbar(im, ax=ax, label="height z / Δmax", extend="min", shrink=0.9)
    centres = st.lattice_centres() / st.radius
    delta = torch.as_tensor(np.maximum(d_max - (design.h - design.h.min()), 0.0))
    a = contact_radius(torch.as_tensor(design.gamma), delta, st.radius).numpy() / st.radius
    for (x, y), r in zip(centres, a, strict=True):
        if r > 0:
            ax.add_patch(Circle((x, y), r, fill=False, color="w", lw=1.0))
    labels = []
    idle = set(idle)
    for k, ((x, y), g, hk) in enumerate(zip(centres, design.gamma, h0, strict=True)):
        # plain text, not mathtext: nine labels of their own would cost nine parses
        state = " idle" if k in idle else ""
        full = f"k = {k}{state}\nγ = {g:.2f}\nh = {_height(hk)} Δmax"
        if k in idle:
            ax.plot([x], [y], "x", color="C3", ms=10, mew=2)
        text = ax.text(
            x,
            y - 0.5 * side / n * 0.92,
            full,
            ha="center",
            va="bottom",
            color="C3" if k in idle else "k",
            bbox={"boxstyle": "round,pad=0.15", "fc": "w", "ec": "none", "alpha": 0.75},
        )
        labels.append((text, f"{k}x" if k in idle else str(k)))
    ax.set(
        xlim=(0, side),
        ylim=(0, side),
        aspect="equal",
        title="cell from above\nwhite: contact at Δmax" + (", red x: idle" if idle else ""),
        xlabel="x / R",
        ylabel="y / R",
    )
    tidy_axis(ax, bins=4)
    return labels


def _fit_labels(fig, ax, labels: list, n: int) -> None:
    """Size the asperity labels to the lattice cell as laid out: three lines when they fit
    (the widest, 'h = 0.45 Delta_max', is about 8 font sizes wide), the index alone when not."""
    fig.get_layout_engine().execute(fig)
    pitch_pt = ax.get_position().width * fig.get_size_inches()[0] * 72 / n
    size = min(8.0, pitch_pt / 8.5)
    for text, index in labels:
        if size < 4.5:
            text.set_text(index)
            text.set_fontsize(min(7.0, max(4.0, pitch_pt / 3)))
        else:
            text.set_fontsize(size)
    # Laid out now; the sizes set above stay inside the axes, so a second pass on saving
    # would find the same positions again. No engine at all (None), not "none": savefig
    # measures every text once more in a draw of its own for any engine, a placeholder too
    # (0.4-0.6 s of the main job's figure, measured).
    fig.set_layout_engine(None)


def _height(h: float) -> str:
    """h / Delta_max in two significant digits, 0 below 0.005 (round-off of 'touching')."""
    return "0" if h < 5e-3 else f"{h:.2g}" if h < 10 else f"{h:.0f}"


def plot_comparison(
    results: Sequence[Sequence], curves: Sequence[Sequence], *, width: float | None = None
) -> Figure:
    """Paper fig. 5: per target (column), the target and each method's design.

    results[i][j]: target i's DesignResult by method j; curves[i][j]: its curve (numpy
    p_star, alpha). width: inches (default 4.2 per target; narrower stacks them)."""
    width = 4.2 * len(results) if width is None else width
    fig, axes = panel_grid(len(results), width, min_panel=3.4, aspect=0.9)
    for ax, per_method, per_curve in zip(axes, results, curves, strict=True):
        t = per_method[0].target
        keep = _every(t.p_star.size)
        ax.plot(t.p_star[keep], t.alpha[keep], "k-", lw=2.5, label="target")
        for r, c in zip(per_method, per_curve, strict=True):
            ax.plot(
                c.p_star,
                c.alpha,
                "--",
                color=COLORS.get(r.method, "C4"),
                label=f"{r.method}: {percent(r.error)}, {r.seconds:.2g} s",
            )
        p_top = 1.03 * max(t.p_star_max, *(float(c.p_star[-1]) for c in per_curve))
        ax.set(xlabel="P*", ylabel="α", title=short(t.name), xlim=(0, p_top))
        ax.set_ylim(bottom=0)
        ax.grid(alpha=0.3)
        tidy_axis(ax)
        ax.legend(fontsize=7, loc="lower right")
    return fig
