"""The interactive page of one design: curves with hover, the cell in 3D, the files to download.

One self-contained HTML file: plotly.js is embedded inline and the files are embedded as
``data:`` URIs, so the page opens from disk in any browser, without a server or a network.
Labels use Unicode (α, Δ), not LaTeX, which would need MathJax from the network.
"""

from __future__ import annotations

import base64
import html
import mimetypes
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from metainterface.errors import MetainterfaceError
from metainterface.plots.common import short

INSTALL = "pip install 'metainterface[view]'"


@dataclass(frozen=True)
class PageFile:
    """A file offered on the page: embedded (``data`` bytes) or linked (``href``, relative to
    the page)."""

    name: str
    size: int
    data: bytes | None = None
    href: str | None = None


def _plotly() -> Any:
    try:
        import plotly.graph_objects as go
        from plotly.subplots import make_subplots
    except ImportError:
        raise MetainterfaceError(f"the HTML view needs plotly: {INSTALL}") from None
    return go, make_subplots


def _size(n: int) -> str:
    for unit, scale in (("MB", 1e6), ("kB", 1e3)):
        if n >= scale:
            return f"{n / scale:.3g} {unit}"
    return f"{n} B"


def _curves_figure(curve, target, units: dict | None) -> Any:
    """alpha(P*), S*(P*) and, for a friction law, friction force and coefficient [N]."""
    go, make_subplots = _plotly()
    titles = ["contact area α(P*)", "stiffness S*(P*)"]
    if units:
        titles += ["friction force vs normal force", "friction coefficient vs normal force"]
    rows = 2 if units else 1
    fig = make_subplots(rows=rows, cols=2, subplot_titles=titles, horizontal_spacing=0.1)
    p_tip = "P* = %{x:.4g}<br>"
    touching = curve.alpha > 0
    if target is not None:
        tp, ta, ts = target
        fig.add_trace(
            go.Scatter(
                x=tp,
                y=ta,
                name="target",
                line={"color": "black", "width": 3},
                hovertemplate=p_tip + "α = %{y:.4g}<extra>target</extra>",
                legendgroup="target",
            ),
            row=1,
            col=1,
        )
        if ts is not None and np.isfinite(ts).any():
            fig.add_trace(
                go.Scatter(
                    x=tp,
                    y=ts,
                    name="target",
                    line={"color": "black", "width": 3},
                    hovertemplate=p_tip + "S* = %{y:.4g}<extra>target</extra>",
                    legendgroup="target",
                    showlegend=False,
                ),
                row=1,
                col=2,
            )
    fig.add_trace(
        go.Scatter(
            x=curve.p_star,
            y=curve.alpha,
            name="design",
            line={"color": "#1f77b4", "dash": "dash"},
            hovertemplate=p_tip + "α = %{y:.4g}<extra>design</extra>",
            legendgroup="design",
        ),
        row=1,
        col=1,
    )
    fig.add_trace(
        go.Scatter(
            x=curve.p_star[touching],
            y=curve.stiffness[touching],
            name="design",
            line={"color": "#1f77b4"},
            hovertemplate=p_tip + "S* = %{y:.4g}<extra>design</extra>",
            legendgroup="design",
            showlegend=False,
        ),
        row=1,
        col=2,
    )
    fig.update_xaxes(title_text="P* = P/E*", exponentformat="e", row=1)
    fig.update_yaxes(title_text="α = A/A_nom", exponentformat="e", row=1, col=1)
    fig.update_yaxes(title_text="S* = dP*/dα", exponentformat="e", row=1, col=2)
    if units:
        _friction_traces(fig, go, curve, units)
    fig.update_layout(
        height=430 * rows,
        margin={"l": 60, "r": 10, "t": 40, "b": 50},
        hovermode="closest",
        legend={"x": 1.02, "y": 1.0, "xanchor": "left"},  # right of the panels: no overlap
        template="plotly_white",
    )
    return fig


def _friction_traces(fig, go, curve, units: dict) -> None:
    tau, e_star, area = units["tau"], units["e_star"], units["area"]
    fn_d, ff_d = curve.p_star * area * e_star, curve.alpha * tau * area
    fn_t, ff_t = units["normal"], units["friction"]
    tip = "F_n = %{x:.4g} N<br>"
    if fn_t.size:
        loaded = fn_t > 0
        law = {"color": "black", "size": 7}
        fig.add_trace(
            go.Scatter(
                x=fn_t,
                y=ff_t,
                mode="markers",
                name="friction law",
                marker=law,
                hovertemplate=tip + "F_f = %{y:.4g} N<extra>friction law</extra>",
            ),
            row=2,
            col=1,
        )
        fig.add_trace(
            go.Scatter(
                x=fn_t[loaded],
                y=ff_t[loaded] / fn_t[loaded],
                mode="markers",
                name="friction law",
                marker=law,
                showlegend=False,
                hovertemplate=tip + "μ = %{y:.4g}<extra>friction law</extra>",
            ),
            row=2,
            col=2,
        )
    fig.add_trace(
        go.Scatter(
            x=fn_d,
            y=ff_d,
            name="design",
            line={"color": "#1f77b4", "dash": "dash"},
            showlegend=False,
            hovertemplate=tip + "F_f = %{y:.4g} N<extra>design</extra>",
        ),
        row=2,
        col=1,
    )
    loaded = fn_d > 0
    mu = ff_d[loaded] / fn_d[loaded]
    fig.add_trace(
        go.Scatter(
            x=fn_d[loaded],
            y=mu,
            name="design",
            line={"color": "#1f77b4", "dash": "dash"},
            showlegend=False,
            hovertemplate=tip + "μ = %{y:.4g}<extra>design</extra>",
        ),
        row=2,
        col=2,
    )
    top = 1.5 * float((ff_t[fn_t > 0] / fn_t[fn_t > 0]).max()) if fn_t.size else None
    fig.update_xaxes(title_text="normal force [N]", row=2)
    fig.update_yaxes(title_text="friction force [N]", row=2, col=1)
    fig.update_yaxes(
        title_text="friction coefficient μ", row=2, col=2, range=[0, top] if top else None
    )


def _cell_figure(heights: np.ndarray, side: float, length_unit: str) -> Any:
    """The cell's height map as a surface, heights in units of Delta_max."""
    go, _ = _plotly()
    m = heights.shape[0]
    xs = (np.arange(m) + 0.5) * side / m
    fig = go.Figure(
        go.Surface(
            x=xs,
            y=xs,
            z=heights,
            colorscale="Viridis",
            cmax=0.0,
            colorbar={"title": {"text": "z / Δmax"}},
            hovertemplate=f"x = %{{x:.3g}} {length_unit}<br>y = %{{y:.3g}} {length_unit}"
            "<br>z = %{z:.3g} Δmax<extra></extra>",
        )
    )
    fig.update_layout(
        height=520,
        margin={"l": 0, "r": 0, "t": 10, "b": 0},
        scene={
            "xaxis": {"title": {"text": f"x [{length_unit}]"}},
            "yaxis": {"title": {"text": f"y [{length_unit}]"}},
            "zaxis": {"title": {"text": "z / Δmax"}, "nticks": 3},
            "aspectmode": "manual",
            "aspectratio": {"x": 1, "y": 1, "z": 0.35},
        },
    )
    return fig


_STYLE = """
body { font-family: system-ui, sans-serif; margin: 1.5em auto; max-width: 1100px;
       padding: 0 1em; color: #222; }
h1 { font-size: 1.5em; margin-bottom: 0.2em; word-break: break-all; }
h2 { font-size: 1.15em; margin-top: 1.4em; border-bottom: 1px solid #ddd; }
table { border-collapse: collapse; font-size: 0.92em; }
td, th { padding: 0.2em 0.8em; text-align: left; border-bottom: 1px solid #eee; }
th { background: #f4f4f4; }
.summary td:first-child { color: #555; }
ul.files li { margin: 0.3em 0; }
footer { margin-top: 2em; color: #777; font-size: 0.8em; }
"""


def design_html(
    *,
    name: str,
    summary: Sequence[tuple[str, str]],
    curve,
    target: tuple[np.ndarray, np.ndarray, np.ndarray | None] | None,
    units: dict | None,
    heights: np.ndarray,
    side: float,
    length_unit: str,
    gamma: np.ndarray,
    h_over_delta: np.ndarray,
    files: Sequence[PageFile],
    footer: str,
) -> str:
    """The page as one HTML string.

    curve: numpy p_star, alpha, stiffness (K,); target: (p_star, alpha, stiffness or None)
    arrays; units: friction units (tau, e_star [Pa], area [m^2], the law's normal and
    friction forces [N]) or None; heights: (M, M) z / Delta_max over a square of ``side``
    (in ``length_unit``); gamma, h_over_delta: (N,) the parameters; files: offered for
    download, embedded when they carry data; summary: (label, value) rows.
    """
    curves = _curves_figure(curve, target, units)
    cell = _cell_figure(heights, side, length_unit)
    config = {"displaylogo": False, "responsive": True}
    curves_div = curves.to_html(
        full_html=False, include_plotlyjs=True, div_id="curves", config=config
    )
    cell_div = cell.to_html(full_html=False, include_plotlyjs=False, div_id="cell", config=config)
    esc = html.escape
    rows = "".join(f"<tr><td>{esc(k)}</td><td>{esc(v)}</td></tr>" for k, v in summary)
    params = "".join(
        f"<tr><td>{k}</td><td>{g:.4f}</td><td>{'0' if hk < 5e-4 else f'{hk:.3g}'}</td></tr>"
        for k, (g, hk) in enumerate(zip(gamma, h_over_delta, strict=True))
    )
    items = []
    for f in files:
        if f.data is not None:
            mime = mimetypes.guess_type(f.name)[0] or "application/octet-stream"
            href = f"data:{mime};base64,{base64.b64encode(f.data).decode('ascii')}"
        else:
            href = esc(f.href or f.name)
        items.append(
            f'<li><a href="{href}" download="{esc(f.name)}">{esc(f.name)}</a> '
            f"({_size(f.size)}{'' if f.data is not None else ', beside this page'})</li>"
        )
    files_html = f'<ul class="files">{"".join(items)}</ul>' if items else "<p>none</p>"
    return f"""<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8">
<meta name="viewport" content="width=device-width, initial-scale=1">
<title>{esc(short(name))}: metainterface design</title>
<style>{_STYLE}</style></head>
<body>
<h1>{esc(short(name, 60))}</h1>
<table class="summary">{rows}</table>
<h2>Contact law: target and design</h2>
{curves_div}
<h2>The unit cell in 3D</h2>
{cell_div}
<h2>Parameters</h2>
<table><tr><th>asperity k</th><th>γ</th><th>h / Δmax</th></tr>{params}</table>
<h2>Files</h2>
{files_html}
<footer>{esc(footer)}</footer>
</body></html>
"""
