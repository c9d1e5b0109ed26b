"""What every output file records: the package version and the settings that made it."""

from __future__ import annotations

import json
import platform
from datetime import UTC, datetime
from typing import Any

import torch


def provenance(**settings: Any) -> dict[str, Any]:
    """A JSON-ready record: package, version, time, python, torch, plus ``settings``."""
    from metainterface import __version__

    return {
        "package": "metainterface",
        "version": __version__,
        "created": datetime.now(UTC).isoformat(timespec="seconds"),
        "python": platform.python_version(),
        "torch": str(torch.__version__),
        "settings": settings,
    }


def csv_header(**settings: Any) -> str:
    """A '# ' comment line for CSV files (numpy and pandas(comment='#') skip it)."""
    return "# " + json.dumps(provenance(**settings), sort_keys=True, default=str) + "\n"
