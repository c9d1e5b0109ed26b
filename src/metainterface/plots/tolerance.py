"""The tolerance figure: the alpha(P*) band of made cells, their errors, the friction law."""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from metainterface.plots.common import new_figure


def _stress_unit(values: np.ndarray) -> tuple[float, str]:
    top = float(np.max(np.abs(values))) if values.size else 1.0
    for scale, unit in ((1e9, "GPa"), (1e6, "MPa"), (1e3, "kPa")):
        if top >= scale:
            return scale, unit
    return 1.0, "Pa"


def plot_tolerance(result) -> Figure:
    """Panels of a :class:`~metainterface.manufacture.tolerance.ToleranceResult`: the 5-95 % band
    of alpha(P*) with the nominal curve, the first-order band and the reference; the
    distribution of the relative curve error; and, with a shear strength and a modulus,
    the band of the friction law (friction stress against normal pressure)."""
    friction = result.shear_strength is not None and result.modulus is not None
    fig = new_figure(13.5 if friction else 9.0, 3.8)
    axes = fig.subplots(1, 3 if friction else 2)
    ax, ax_e = axes[0], axes[1]
    p = result.p_star
    s = result.settings
    if result.modulus is not None:
        scale, unit = _stress_unit(p * result.modulus)
        top = ax.secondary_xaxis(
            "top",
            functions=(lambda x: x * result.modulus / scale, lambda x: x * scale / result.modulus),
        )
        top.set_xlabel(f"pressure P [{unit}]", fontsize=8)
    ax.fill_between(
        p,
        result.alpha_p05,
        result.alpha_p95,
        color="C0",
        alpha=0.3,
        lw=0,
        label="made cells, 5-95 %",
    )
    ax.plot(p, result.alpha_p50, color="C0", lw=1, label="median")
    ax.plot(p, result.alpha_nominal, color="C3", lw=1.2, label="nominal design")
    ax.plot(p, result.alpha_p05_linear, color="C1", ls=":", lw=1.2, label="first order, 5-95 %")
    ax.plot(p, result.alpha_p95_linear, color="C1", ls=":", lw=1.2)
    if result.reference is not None:
        t = result.reference
        ax.plot(t.p_star, t.alpha, "k--", lw=1, label=f"target {t.name}")
    ax.set(xlabel=r"$P^* = P/E^*$", ylabel=r"$\alpha = A/A_{nom}$")
    # the limits hold the design and its target; where the design stops short, marked
    p_ref = float(result.reference.p_star[-1]) if result.reference is not None else 0.0
    ax.set_xlim(0, max(float(p[-1]), p_ref))
    if p_ref > 1.001 * float(p[-1]):
        ax.axvline(float(p[-1]), color="C3", ls=":", lw=1.2, label="design stops")
    ax.set_ylim(bottom=0)
    ax.grid(alpha=0.3)
    ax.ticklabel_format(axis="x", style="sci", scilimits=(-2, 3))
    ax.legend(fontsize=7, loc="lower right")
    sig = f"$\\sigma_h$ = {s.sigma_h:.3g} R"
    if s.radius_m is not None:
        sig += f" = {s.sigma_h * s.radius_m * 1e6:.3g} um (R = {s.radius_m * 1e3:.3g} mm)"
    ax.set_title(
        f"{sig}, $\\sigma_\\gamma$ = {s.sigma_gamma:g}, scale {s.scale_sigma:g}", fontsize=8
    )

    err = 100 * result.errors
    ax_e.hist(err, bins=60, color="C0", alpha=0.6, label=f"{s.samples} made cells")
    for value, style, label in (
        (result.error_median, "-", "median"),
        (result.error_p95, "--", "p95"),
    ):
        ax_e.axvline(100 * value, color="C0", ls=style, label=f"{label} {100 * value:.3g} %")
    for value, style, label in (
        (result.error_median_linear, "-", "first-order median"),
        (result.error_p95_linear, "--", "first-order p95"),
    ):
        ax_e.axvline(100 * value, color="C1", ls=style, label=f"{label} {100 * value:.3g} %")
    if result.error_nominal > 0:
        ax_e.axvline(100 * result.error_nominal, color="C3", label="nominal design")
    ax_e.set(xlabel=f"curve error to the {s.reference} [%]", ylabel="made cells")
    ax_e.grid(alpha=0.3)
    ax_e.legend(fontsize=7)

    if friction:
        ax_f = axes[2]
        pressure = p * result.modulus
        ps, pu = _stress_unit(pressure)
        fs, fu = _stress_unit(result.alpha_p95 * result.shear_strength)
        tau = result.shear_strength / fs
        ax_f.fill_between(
            pressure / ps,
            tau * result.alpha_p05,
            tau * result.alpha_p95,
            color="C0",
            alpha=0.3,
            lw=0,
            label="made cells, 5-95 %",
        )
        ax_f.plot(
            pressure / ps, tau * result.alpha_nominal, color="C3", lw=1.2, label="nominal design"
        )
        if result.reference is not None:
            t = result.reference
            ax_f.plot(
                t.p_star * result.modulus / ps, tau * t.alpha, "k--", lw=1, label=f"target {t.name}"
            )
        ax_f.set(
            xlabel=f"normal pressure [{pu}]",
            ylabel=f"friction stress $\\tau\\,\\alpha$ [{fu}]",
            title="friction law (Bowden-Tabor)",
        )
        ax_f.set_xlim(0, max(float(pressure[-1]), p_ref * result.modulus) / ps)
        if p_ref > 1.001 * float(p[-1]):
            ax_f.axvline(float(pressure[-1] / ps), color="C3", ls=":", lw=1.2, label="design stops")
        ax_f.set_ylim(bottom=0)
        ax_f.grid(alpha=0.3)
        ax_f.legend(fontsize=7, loc="lower right")
    fig.suptitle(f"tolerance ({s.model}, seed {s.seed})", fontsize=9)
    return fig
