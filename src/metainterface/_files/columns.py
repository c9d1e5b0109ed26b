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


#: Largest text file read whole (a CSV of this size holds millions of rows).
MAX_TEXT_BYTES = 256 * 2**20


def read_text_lines(path: str | os.PathLike[str]) -> list[str]:
    """The lines of a small text file as spreadsheets write it: UTF-8 with or without a byte
    order mark, else Windows-1252/Latin-1; any line ending. One-line errors."""
    path = Path(path)
    if path.exists() and not path.is_file() and not path.is_dir():  # a FIFO would block
        raise MetainterfaceError(f"{path}: not a regular file")
    try:
        if path.stat().st_size > MAX_TEXT_BYTES:
            raise MetainterfaceError(
                f"{path}: {path.stat().st_size / 2**20:.0f} MiB, larger than the "
                f"{MAX_TEXT_BYTES // 2**20} MiB a CSV may have"
            )
        data = path.read_bytes()
    except FileNotFoundError:
        raise MetainterfaceError(f"{path}: file not found") from None
    except IsADirectoryError:
        raise MetainterfaceError(f"{path}: is a folder, expected a CSV file") from None
    except OSError as exc:
        raise MetainterfaceError(f"{path}: cannot read ({exc.strerror})") from None
    if b"\0" in data:
        raise MetainterfaceError(f"{path}: binary data, expected a text (CSV) file")
    data = data.removeprefix(b"\xef\xbb\xbf")
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError:  # numbers and column names are ASCII: any 8-bit text will do
        text = data.decode("cp1252", errors="replace")
    return text.splitlines()


def _cell(text: str) -> str:
    """A CSV cell without surrounding blanks or double quotes (spreadsheets add them)."""
    text = text.strip()
    if len(text) >= 2 and text[0] == text[-1] == '"':
        text = text[1:-1].strip()
    return text


def read_columns(path: str | os.PathLike[str], required: Sequence[str]) -> dict[str, np.ndarray]:
    """Read a numeric CSV with a header row ('#' lines skipped); check required columns.

    Errors name the file, the row (1-based data row) or the missing column.
    """
    path = Path(path)
    lines = read_text_lines(path)
    rows = [ln for ln in lines if ln.strip() and not ln.lstrip().startswith("#")]
    if not rows:
        raise MetainterfaceError(f"{path}: empty file, expected a header {','.join(required)}")
    header = [_cell(c) for c in rows[0].split(",")]
    missing = [c for c in required if c not in header]
    if missing:
        raise MetainterfaceError(
            f"{path}: missing column(s) {', '.join(missing)}; header must contain "
            f"{','.join(required)} (found {','.join(header)})"
        )
    values: list[list[float]] = []
    for i, line in enumerate(rows[1:], start=1):
        cells = [_cell(c) for c in line.split(",")]
        if len(cells) != len(header):
            raise MetainterfaceError(
                f"{path}: row {i} has {len(cells)} values, the header has {len(header)}"
            )
        try:
            values.append([float(c) for c in cells])
        except ValueError:
            shown = line if len(line) <= 80 else line[:77] + "..."
            raise MetainterfaceError(f"{path}: row {i} is not numeric: {shown!r}") from None
    arr = np.asarray(values, dtype=np.float64).reshape(-1, len(header))
    return {name: arr[:, header.index(name)] for name in required}
