"""Files at the edge of the package: design files, CSV, atomic writes, provenance."""

from metainterface.io.atomic import atomic_open, ensure_parent, write_bytes, write_text
from metainterface.io.csvfiles import read_columns, write_columns
from metainterface.io.design_file import (
    FORMAT,
    design_from_dict,
    design_to_dict,
    load_design,
    save_design,
)
from metainterface.io.provenance import csv_header, provenance

__all__ = [
    "FORMAT",
    "atomic_open",
    "csv_header",
    "design_from_dict",
    "design_to_dict",
    "ensure_parent",
    "load_design",
    "provenance",
    "read_columns",
    "save_design",
    "write_bytes",
    "write_columns",
    "write_text",
]
