"""Small CSV files with a provenance comment line, written atomically."""

from __future__ import annotations

import csv
import io
import os
import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
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


#: Column separators, in the order a header line is searched for them.
SEPARATORS = {"\t": "tab", ";": "semicolon", ",": "comma"}
# A number written with a decimal comma: "1,5", "-0,25", ",5", "1,5e-3".
_DECIMAL_COMMA = re.compile(r"^[-+]?(?:\d+,\d*|,\d+)(?:[eE][-+]?\d+)?$")
# What a thousands separator would look like: "1,234" or "12,345,678" (ambiguous in a tab file).
_THOUSANDS = re.compile(r"^[-+]?[1-9]\d{0,2}(?:,\d{3})+$")
# A header cell: a name, then maybe a unit in brackets or parentheses: "normal_force [mN]".
_NAME_UNIT = re.compile(r"^(.*?)\s*(?:\[([^\]]*)\]|\(([^)]*)\))$")


@dataclass(frozen=True)
class Table:
    """A numeric CSV as read: column names (lower case, inner blanks as '_'), each column's
    unit text as written in the header (None without one), the values (rows, columns) in
    the order of the data rows (comment and blank lines not counted), and the separator's
    name ('comma', 'semicolon', 'tab')."""

    path: Path
    names: list[str]
    units: list[str | None]
    values: np.ndarray
    separator: str

    def column(self, name: str) -> np.ndarray:
        """The values of the column ``name`` (rows,)."""
        return self.values[:, self.names.index(name)]

    def unit(self, name: str) -> str | None:
        """The unit text written for ``name``, or None."""
        return self.units[self.names.index(name)]


def _cell(text: str) -> str:
    """A CSV cell without surrounding blanks or double quotes (spreadsheets add them)."""
    text = text.strip()
    if len(text) >= 2 and text[0] == text[-1] == '"':
        text = text[1:-1].strip()
    return text


def _split(path: Path, line: str, separator: str) -> list[str]:
    """The cells of one line (double-quoted cells may hold the separator)."""
    try:
        cells = next(csv.reader([line], delimiter=separator, skipinitialspace=True))
    except csv.Error as exc:
        raise MetainterfaceError(f"{path}: cannot split a line into cells ({exc})") from None
    cells = [_cell(c) for c in cells]
    while len(cells) > 1 and not cells[-1]:  # a trailing separator, as some exports write
        cells.pop()
    return cells


def header_name(cell: str, known: Sequence[str] = ()) -> tuple[str, str | None]:
    """(name, unit) of a header cell: ``'Normal_Force [mN]'``, ``'normal_force (N)'`` or, for
    a name in ``known``, ``'normal_force_mN'`` give ('normal_force', 'mN'). The name is read
    in lower case with inner blanks as '_'; the unit is kept as written (mN is not MN);
    ``[-]``, ``[1]`` and ``[]`` mark no unit (None)."""
    cell = cell.strip()
    unit: str | None = None
    match = _NAME_UNIT.match(cell)
    if match:
        cell, unit = (
            match.group(1),
            (match.group(2) if match.group(2) is not None else match.group(3)),
        )
        unit = unit.strip()
        if unit in ("", "-", "1"):  # '[-]', '[1]': the usual marks of a dimensionless column
            unit = None
    name = re.sub(r"\s+", "_", cell.strip()).lower()
    if unit is None:
        for k in known:
            if name.startswith(k + "_") and len(name) > len(k) + 1:
                return k, cell.strip()[len(k) + 1 :]
    return name, unit


def _number(path: Path, row: int, column: str, text: str, decimal_comma: bool) -> float:
    if "," in text:
        if not decimal_comma or not _DECIMAL_COMMA.match(text):
            raise MetainterfaceError(
                f"{path}: row {row}, column {column}: {text!r} is not a number"
                + ("" if decimal_comma else " (a decimal comma needs ';' or tab as separator)")
            )
        text = text.replace(",", ".")
    try:
        return float(text)
    except ValueError:
        shown = text if len(text) <= 40 else text[:37] + "..."
        raise MetainterfaceError(
            f"{path}: row {row}, column {column}: {shown!r} is not a number"
        ) from None


def read_table(
    path: str | os.PathLike[str],
    known: Sequence[str] = (),
    numeric: Sequence[str] | None = None,
) -> Table:
    """Read a numeric CSV as labs and spreadsheets write it.

    The separator (tab, ';' or ',') is the first of them found in the header line; with ';'
    or tab, numbers may have a decimal comma ('1,5'), all of the file the same way. '#'
    lines and blank lines are skipped; a byte order mark is dropped. Header cells may carry
    a unit (see :func:`header_name`; ``known`` names take one after '_'). Only the columns
    in ``numeric`` (default: all) are read as numbers, the others are NaN (a column of notes
    is ignored). Errors are one line naming the file, the row (1-based data row) and the
    column.
    """
    path = Path(path)
    lines = [ln for ln in read_text_lines(path) if ln.strip() and not ln.lstrip().startswith("#")]
    if not lines:
        raise MetainterfaceError(f"{path}: empty file, expected a header row")
    separator = next((s for s in SEPARATORS if s in lines[0]), ",")
    cells = _split(path, lines[0], separator)
    parsed = [header_name(c, known) for c in cells]
    names = [n for n, _ in parsed]
    for name in names:
        if not name:
            raise MetainterfaceError(f"{path}: the header has an empty column name")
        if names.count(name) > 1:
            raise MetainterfaceError(f"{path}: column {name} appears twice in the header")
    rows = [_split(path, line, separator) for line in lines[1:]]
    for i, row in enumerate(rows, start=1):
        if len(row) != len(names):
            hint = ""
            if separator == "," and len(row) > len(names):
                hint = (
                    "; if these are decimal commas, a comma separator makes them ambiguous: "
                    "separate the columns with ';' (or tab), or write decimal points"
                )
            raise MetainterfaceError(
                f"{path}: row {i} has {len(row)} values, the header has {len(names)}{hint}"
            )
    keep = [k for k, n in enumerate(names) if numeric is None or n in numeric]
    decimal_comma = separator != "," and any("," in row[k] for row in rows for k in keep)
    for i, row in enumerate(rows, start=1):
        for name, text in ((names[k], row[k]) for k in keep):
            if decimal_comma and "." in text and not text.lower().endswith(("inf", "nan")):
                raise MetainterfaceError(
                    f"{path}: row {i}, column {name}: {text!r} has a decimal point in a file "
                    f"with decimal commas; write all numbers one way"
                )
            if decimal_comma and separator == "\t" and _THOUSANDS.match(text):
                raise MetainterfaceError(
                    f"{path}: row {i}, column {name}: {text!r} is ambiguous (a decimal comma or "
                    f"a thousands separator?); write it with a decimal point"
                )
    arr = np.full((len(rows), len(names)), np.nan)
    for i, row in enumerate(rows, start=1):
        for k in keep:
            arr[i - 1, k] = _number(path, i, names[k], row[k], decimal_comma)
    return Table(path, names, [u for _, u in parsed], arr, SEPARATORS[separator])


def read_columns(path: str | os.PathLike[str], required: Sequence[str]) -> dict[str, np.ndarray]:
    """Read a numeric CSV of dimensionless columns (:func:`read_table`); check required columns.

    Errors name the file, the row (1-based data row) and the column, or the missing column;
    a unit in the header of a required column is an error (these columns have none).
    """
    table = read_table(path, numeric=required)
    missing = [c for c in required if c not in table.names]
    if missing:
        raise MetainterfaceError(
            f"{table.path}: missing column(s) {', '.join(missing)}; header must contain "
            f"{','.join(required)} (found {','.join(table.names)})"
        )
    for name in required:
        if table.unit(name) is not None:
            raise MetainterfaceError(
                f"{table.path}: column {name} [{table.unit(name)}]: {name} is dimensionless, "
                f"write it without a unit"
            )
    return {name: table.column(name) for name in required}
