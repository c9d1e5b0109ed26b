"""What every output file records: the package version and the settings that made it."""

from __future__ import annotations

import json
import platform
from datetime import UTC, datetime
from typing import Any

import torch


def provenance(*, stamp: bool = True, **settings: Any) -> dict[str, Any]:
    """A JSON-ready record: package, version, time, python, torch, plus ``settings``.

    ``stamp=False`` leaves the creation time out, for files that must be byte-identical
    when made again with the same seed (the time then goes into a file beside them)."""
    from metainterface import __version__

    record = {
        "package": "metainterface",
        "version": __version__,
        "created": datetime.now(UTC).isoformat(timespec="seconds"),
        "python": platform.python_version(),
        "torch": str(torch.__version__),
        "settings": settings,
    }
    if not stamp:
        del record["created"]
    return record


def csv_header(*, stamp: bool = True, **settings: Any) -> str:
    """A '# ' comment line for CSV files (numpy and pandas(comment='#') skip it)."""
    record = provenance(stamp=stamp, **settings)
    return "# " + json.dumps(record, sort_keys=True, default=str) + "\n"
