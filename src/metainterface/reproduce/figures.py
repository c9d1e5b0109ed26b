"""The paper's figures that have no general-purpose plot in ``metainterface.plots``.

fig. 1 (single power-law asperities), fig. 4e-f (the contact regularisation of one design) and
the wall case (zero-shot prediction against the ground-truth parameters). Data in, Figure out;
the numbers are computed by the caller (``metainterface.reproduce.stages``).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np
from matplotlib import colormaps
from matplotlib.figure import Figure

from metainterface.plots.common import new_figure


def plot_asperities(
    r: np.ndarray,
    profiles: Mapping[float, np.ndarray],
    force: np.ndarray,
    areas: Mapping[float, np.ndarray],
    envelope: tuple[np.ndarray, np.ndarray],
    cone: np.ndarray,
    flat: float,
) -> Figure:
    """fig. 1a-b: profiles f(r) = c r^gamma (dark: cone, light: gamma = 100) and A(F) per gamma.

    r: (M,) radial coordinate / R; profiles: gamma -> (M,) f / R. force: (K,) F / (E* R^2);
    areas: gamma -> (K,) A / R^2 (NaN where the shape does not reach that load); envelope:
    (lower, upper) (K,) of all shapes in [1, 100]; cone: (K,) A of the cone; flat: the
    flat-punch area pi R^2.
    """
    fig = new_figure(10.0, 4.0)
    ax_a, ax_b = fig.subplots(1, 2)
    gammas = sorted(profiles)
    shades = np.linspace(0.0, 0.8, len(gammas))
    for g, s in zip(gammas, shades, strict=True):
        color = str(s)
        ax_a.plot(r, profiles[g], color=color, lw=1.5, label=rf"$\gamma = {g:g}$")
        ax_b.loglog(force, areas[g], color=color, lw=1.2)
    ax_a.set(
        xlabel="r / R",
        ylabel="f(r) / R",
        title=r"(a) profiles $f = c\,|r|^\gamma$, $c = 1/(2R^{\gamma-1})$",
    )
    ax_a.legend(fontsize=7, ncol=2)
    ax_a.grid(alpha=0.3)
    ax_b.fill_between(force, envelope[0], envelope[1], color="0.85", zorder=0)
    ax_b.loglog(force, cone, "k--", lw=1, label=r"cone: $A = 4F/E^*$ ($A \sim F$)")
    ax_b.axhline(flat, color="k", ls=":", lw=1, label=r"flat punch: $A = \pi R^2$")
    ax_b.set(
        xlabel=r"$F / (E^* R^2)$",
        ylabel=r"$A / R^2$",
        title=r"(b) single asperity: $A \sim F^{2/(\gamma+1)}$",
    )
    ax_b.legend(fontsize=7, loc="lower right")
    ax_b.grid(alpha=0.3)
    return fig


def plot_regularisation(
    p_hat: np.ndarray,
    kappas: Sequence[float],
    alpha_hat: np.ndarray,
    stiffness_hat: np.ndarray,
    exact: tuple[np.ndarray, np.ndarray],
    title: str,
) -> Figure:
    """fig. 4e-f: alpha_hat and S_hat against P_hat for softplus steepnesses ``kappas``.

    alpha_hat, stiffness_hat: (len(kappas), n); exact: the (alpha_hat, S_hat) of the exact
    bracket, drawn dashed black. Light blue: the smallest kappa, dark blue: the largest.
    """
    fig = new_figure(10.0, 3.8)
    ax_e, ax_f = fig.subplots(1, 2)
    colors = colormaps["Blues"](np.linspace(0.35, 1.0, len(kappas)))
    for k, c, a, s in zip(kappas, colors, alpha_hat, stiffness_hat, strict=True):
        label = rf"$\kappa = 10^{{{np.log10(k):.1f}}}$"
        ax_e.plot(p_hat, a, color=c, lw=1.6, label=label)
        ax_f.plot(p_hat, s, color=c, lw=1.6, label=label)
    ax_e.plot(p_hat, exact[0], "k--", lw=1, label="exact bracket")
    ax_f.plot(p_hat, exact[1], "k--", lw=1, label="exact bracket")
    ax_e.set(xlabel=r"$\hat P$", ylabel=r"$\hat\alpha$", title="(e) normalised contact area")
    ax_f.set(xlabel=r"$\hat P$", ylabel=r"$\hat S = d\hat P/d\hat\alpha$", title="(f) stiffness")
    for ax in (ax_e, ax_f):
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7)
    fig.suptitle(title, fontsize=9)
    return fig


def plot_wall_case(
    truth: Mapping[str, np.ndarray],
    pred: Mapping[str, np.ndarray],
    delta_max: float,
    title: str,
) -> Figure:
    """The wall case: alpha(P*) and S*(P*) of a test design and of the zero-shot prediction
    (left), and their h / Delta_max and gamma per asperity (right).

    truth, pred: arrays p_star, alpha, stiffness (K,) of the exact curve and gamma, h (N,).
    """
    fig = new_figure(10.0, 6.5)
    axes = fig.subplots(2, 2)
    ax_a, ax_h = axes[0]
    ax_s, ax_g = axes[1]
    for data, style, label in ((truth, "k-", "ground truth"), (pred, "C0--", "zero-shot NN")):
        ax_a.plot(data["p_star"], data["alpha"], style, lw=1.8, label=label)
        ax_s.plot(data["p_star"], data["stiffness"], style, lw=1.4, label=label)
    k = np.arange(truth["gamma"].size) + 1
    ax_h.bar(k - 0.2, truth["h"] / delta_max, 0.4, color="k", label="ground truth")
    ax_h.bar(k + 0.2, pred["h"] / delta_max, 0.4, color="C0", label="zero-shot NN")
    ax_g.bar(k - 0.2, truth["gamma"], 0.4, color="k", label="ground truth")
    ax_g.bar(k + 0.2, pred["gamma"], 0.4, color="C0", label="zero-shot NN")
    ax_a.set(xlabel="$P^*$", ylabel=r"$\alpha$", title="(a) contact area")
    ax_s.set(xlabel="$P^*$", ylabel=r"$S^* = dP^*/d\alpha$", title="(c) stiffness")
    ax_h.set(xlabel="asperity", ylabel=r"$h/\Delta_{max}$", title="(b) height offsets")
    ax_g.set(xlabel="asperity", ylabel=r"$\gamma$", title="(d) shape exponents")
    for ax in axes.flat:
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7)
    for ax in (ax_h, ax_g):
        ax.set_xticks(k)
    fig.suptitle(title, fontsize=9)
    return fig
