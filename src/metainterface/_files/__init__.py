"""Generic file helpers every layer may use: atomic writes, provenance records, CSV columns.

They know nothing of the domain (no physics, no designs), so the engine can checkpoint and
stream results without importing the format layer (``metainterface.io``) above it.
"""

from metainterface._files.atomic import (
    atomic_open,
    atomic_path,
    check_output_file,
    check_output_folder,
    ensure_parent,
    output_set,
    sweep_stale,
    terminate_as_interrupt,
    write_bytes,
    write_text,
)
from metainterface._files.columns import read_columns, write_columns
from metainterface._files.provenance import (
    compact_provenance,
    csv_header,
    provenance,
    short_hash,
)
from metainterface._files.strict_json import dumps, finite_or_none

__all__ = [
    "atomic_open",
    "atomic_path",
    "check_output_file",
    "check_output_folder",
    "compact_provenance",
    "csv_header",
    "dumps",
    "ensure_parent",
    "finite_or_none",
    "output_set",
    "provenance",
    "read_columns",
    "short_hash",
    "sweep_stale",
    "terminate_as_interrupt",
    "write_bytes",
    "write_columns",
    "write_text",
]
