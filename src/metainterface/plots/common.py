"""Figure plumbing: no pyplot state, atomic saves, provenance in the file's metadata, and the
small formatting rules every figure shares (errors with significant digits, short titles,
tick labels that never run together)."""

from __future__ import annotations

import io
import math
import os
from pathlib import Path
from typing import Any

from matplotlib.axes import Axes
from matplotlib.figure import Figure
from matplotlib.ticker import FuncFormatter, MaxNLocator, ScalarFormatter

from metainterface._files import strict_json
from metainterface._files.atomic import write_bytes
from metainterface._files.provenance import compact_provenance
from metainterface.errors import MetainterfaceError

_FORMATS = {".png": "png", ".pdf": "pdf", ".svg": "svg"}
#: Digits and minus as superscripts: a power of ten in plain text ('×10⁻³'), not mathtext,
#: whose parser costs a figure 0.3 s or more to build.
_SUPERSCRIPT = str.maketrans("-0123456789", "⁻⁰¹²³⁴⁵⁶⁷⁸⁹")
#: Longest title text drawn; longer names are cut in the middle.
TITLE_CHARS = 40


def new_figure(width: float = 9.0, height: float = 3.6) -> Figure:
    """A figure with constrained layout, independent of any pyplot backend."""
    return Figure(figsize=(width, height), layout="constrained")


def panel_grid(
    panels: int,
    width: float,
    *,
    min_panel: float = 2.8,
    max_cols: int | None = None,
    aspect: float = 0.8,
) -> tuple[Figure, list[Axes]]:
    """A figure of ``width`` inches with ``panels`` axes, as many per row as fit at least
    ``min_panel`` inches each (at most ``max_cols``): a narrow figure stacks its panels
    rather than squeezing their labels together. aspect: panel height / panel width."""
    if not (math.isfinite(width) and width > 0):
        raise MetainterfaceError(f"width must be a number of inches > 0, got {width!r}")
    cols = max(1, min(panels, max_cols or panels, int(width // min_panel)))
    rows = -(-panels // cols)
    fig = new_figure(width, rows * width / cols * aspect + 0.3)
    axes = list(fig.subplots(rows, cols, squeeze=False).ravel())
    for ax in axes[panels:]:
        ax.remove()
    return fig, axes[:panels]


def percent(x: float) -> str:
    """A relative error in per cent with significant digits: '9.7e-06 %', '2.5 %'."""
    return f"{100 * x:.2g} %" if abs(100 * x) < 1 else f"{100 * x:.3g} %"


def short(name: str, most: int = TITLE_CHARS) -> str:
    """A name for a title: the last path part, cut in the middle when longer than ``most``."""
    name = Path(str(name)).name or str(name)
    if len(name) <= most:
        return name
    half = (most - 1) // 2
    return name[:half] + "…" + name[-(most - 1 - half) :]


def tidy_axis(ax: Axes, *, x: bool = True, y: bool = True, bins: int = 5) -> None:
    """At most ``bins`` short tick labels per axis, so labels of small numbers (P* ~ 1e-3)
    never run into each other: a power of ten the values share moves into the axis label
    ('P* (x 10^-3)'), where it cannot collide with a title the way an offset text does.
    Call it after the limits are set."""
    for on, axis, lim, label in (
        (x, ax.xaxis, ax.get_xlim(), ax.get_xlabel()),
        (y, ax.yaxis, ax.get_ylim(), ax.get_ylabel()),
    ):
        if not on or axis.get_scale() != "linear":
            continue
        axis.set_major_locator(MaxNLocator(bins))
        top = max(abs(lim[0]), abs(lim[1]))
        power = math.floor(math.log10(top)) if top > 0 and math.isfinite(top) else 0
        # side by side on an x axis, plain labels from 10^-2 down need 4+ decimals
        # ('0.0025') and run together; stacked on a y axis they do not
        if (-1 if axis is ax.xaxis else -2) <= power <= 3:
            fmt = ScalarFormatter(useOffset=False)
            fmt.set_scientific(False)
            axis.set_major_formatter(fmt)
            continue
        scale = 10.0**power
        axis.set_major_formatter(FuncFormatter(lambda v, _pos, s=scale: f"{v / s:.4g}"))
        axis.set_label_text(f"{label} (×10{str(power).translate(_SUPERSCRIPT)})")


def save_figure(fig: Figure, path: str | os.PathLike[str], **settings: Any) -> Path:
    """Atomically save ``fig`` as PNG, PDF or SVG (by suffix), recording provenance (long
    settings as their hash, see ``compact_provenance``)."""
    path = Path(path)
    fmt = _FORMATS.get(path.suffix.lower())
    if fmt is None:
        raise MetainterfaceError(
            f"figure {path}: unknown suffix {path.suffix!r}, use one of {', '.join(_FORMATS)}"
        )
    record = strict_json.dumps(compact_provenance(**settings), default=str)
    meta = {
        "png": {"Software": "metainterface", "Description": record},
        "pdf": {"Creator": "metainterface", "Subject": record},
        "svg": {"Description": record},
    }[fmt]
    buf = io.BytesIO()
    # zlib level 3, not PIL's 6: a third less time encoding for files about 10 % larger
    extra = {"pil_kwargs": {"compress_level": 3}} if fmt == "png" else {}
    fig.savefig(buf, format=fmt, dpi=150, metadata=meta, **extra)
    return write_bytes(path, buf.getvalue())
