"""Small CSV files with a provenance comment line, written atomically."""

from __future__ import annotations

import io
import os
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from metainterface._files.atomic import write_text
from metainterface._files.provenance import csv_header
from metainterface.errors import MetainterfaceError


def write_columns(
    path: str | os.PathLike[str],
    columns: Mapping[str, Sequence[float] | np.ndarray],
    *,
    stamp: bool = True,
    **settings: Any,
) -> Path:
    """Write equal-length numeric columns to a CSV with a header row and a '# ' comment line
    (without the creation time if ``stamp`` is False: then the same data give the same bytes)."""
    names = list(columns)
    data = np.column_stack([np.asarray(columns[n], dtype=np.float64) for n in names])
    buf = io.StringIO()
    buf.write(csv_header(stamp=stamp, **settings))
    np.savetxt(buf, data, delimiter=",", header=",".join(names), comments="", fmt="%.10g")
    return write_text(path, buf.getvalue())


def read_columns(path: str | os.PathLike[str], required: Sequence[str]) -> dict[str, np.ndarray]:
    """Read a numeric CSV with a header row ('#' lines skipped); check required columns.

    Errors name the file, the row (1-based data row) or the missing column.
    """
    path = Path(path)
    try:
        lines = path.read_text(encoding="utf-8").splitlines()
    except FileNotFoundError:
        raise MetainterfaceError(f"{path}: file not found") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise MetainterfaceError(f"{path}: cannot read ({exc})") from None
    rows = [ln for ln in lines if ln.strip() and not ln.lstrip().startswith("#")]
    if not rows:
        raise MetainterfaceError(f"{path}: empty file, expected a header {','.join(required)}")
    header = [c.strip() for c in rows[0].split(",")]
    missing = [c for c in required if c not in header]
    if missing:
        raise MetainterfaceError(
            f"{path}: missing column(s) {', '.join(missing)}; header must contain "
            f"{','.join(required)} (found {','.join(header)})"
        )
    values: list[list[float]] = []
    for i, line in enumerate(rows[1:], start=1):
        cells = [c.strip() for c in line.split(",")]
        if len(cells) != len(header):
            raise MetainterfaceError(
                f"{path}: row {i} has {len(cells)} values, the header has {len(header)}"
            )
        try:
            values.append([float(c) for c in cells])
        except ValueError:
            raise MetainterfaceError(f"{path}: row {i} is not numeric: {line!r}") from None
    arr = np.asarray(values, dtype=np.float64).reshape(-1, len(header))
    return {name: arr[:, header.index(name)] for name in required}
