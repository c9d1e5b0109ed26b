"""Generic file helpers every layer may use: atomic writes, provenance records, CSV columns.

They know nothing of the domain (no physics, no designs), so the engine can checkpoint and
stream results without importing the format layer (``metainterface.io``) above it.
"""

from metainterface._files.atomic import (
    atomic_open,
    atomic_path,
    ensure_parent,
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

__all__ = [
    "atomic_open",
    "atomic_path",
    "compact_provenance",
    "csv_header",
    "ensure_parent",
    "provenance",
    "read_columns",
    "short_hash",
    "write_bytes",
    "write_columns",
    "write_text",
]
