"""The monotone fit of a measured friction law, drawn with the raw points and residuals."""

from __future__ import annotations

from typing import Any

import numpy as np
from matplotlib.figure import Figure

from metainterface.plots.common import new_figure, short, tidy_axis


def plot_friction_fit(friction: dict[str, Any], name: str = "friction law") -> Figure:
    """A fitted friction law: ``friction`` is a target's ``meta["friction"]`` (the law
    ``normal_force_n``, ``friction_force_n`` [N] and its ``fit``, with the raw rows). Left
    the measured rows and the fit, right the residuals data - fit."""
    fit = friction["fit"]
    fig = new_figure(9.0, 3.4)
    ax, res = fig.subplots(1, 2, width_ratios=(3, 2))
    fn = np.asarray(fit["raw_normal_force_n"])
    ff = np.asarray(fit["raw_friction_force_n"])
    law_fn = np.asarray(friction["normal_force_n"])
    law_ff = np.asarray(friction["friction_force_n"])
    ax.plot(fn, ff, "o", ms=4, color="0.45", label=f"measured ({fn.size} rows)")
    ax.plot(law_fn, law_ff, "-", color="C0", lw=2, label="monotone fit")
    ax.set_xlabel("normal force $F_n$ (N)")
    ax.set_ylabel("friction force $F_f$ (N)")
    ax.set_xlim(0, None)
    ax.set_ylim(0, None)
    ax.legend(loc="lower right", fontsize=8)
    ax.set_title(short(name), fontsize=10)
    tidy_axis(ax)
    resid = ff - np.interp(fn, law_fn, law_ff)
    res.axhline(0.0, color="0.6", lw=0.8)
    res.plot(fn, resid, "o", ms=4, color="C3")
    res.set_xlabel("normal force $F_n$ (N)")
    res.set_ylabel("data - fit (N)")
    res.set_title(f"rms residual {fit['residual_rms_n']:.3g} N", fontsize=10)
    res.set_xlim(0, None)
    tidy_axis(res)
    return fig
