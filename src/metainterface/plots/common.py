"""Figure plumbing: no pyplot state, atomic saves, provenance in the file's metadata."""

from __future__ import annotations

import io
import json
import os
from pathlib import Path
from typing import Any

from matplotlib.figure import Figure

from metainterface._files.atomic import write_bytes
from metainterface._files.provenance import provenance
from metainterface.errors import MetainterfaceError

_FORMATS = {".png": "png", ".pdf": "pdf", ".svg": "svg"}


def new_figure(width: float = 9.0, height: float = 3.6) -> Figure:
    """A figure with constrained layout, independent of any pyplot backend."""
    return Figure(figsize=(width, height), layout="constrained")


def save_figure(fig: Figure, path: str | os.PathLike[str], **settings: Any) -> Path:
    """Atomically save ``fig`` as PNG, PDF or SVG (by suffix), recording provenance."""
    path = Path(path)
    fmt = _FORMATS.get(path.suffix.lower())
    if fmt is None:
        raise MetainterfaceError(
            f"figure {path}: unknown suffix {path.suffix!r}, use one of {', '.join(_FORMATS)}"
        )
    record = json.dumps(provenance(**settings), default=str)
    meta = {
        "png": {"Software": "metainterface", "Description": record},
        "pdf": {"Creator": "metainterface", "Subject": record},
        "svg": {"Description": record},
    }[fmt]
    buf = io.BytesIO()
    fig.savefig(buf, format=fmt, dpi=150, metadata=meta)
    return write_bytes(path, buf.getvalue())
