"""What every output file records: the package version and the settings that made it.

:func:`provenance` keeps the settings whole (a dataset rebuilds its cell from them).
:func:`compact_provenance`, for the one-line records of CSV files and figures, keeps them
small: a value whose JSON form is longer than ``MAX_INLINE`` characters (a whole design, a
list of loads, a target) is recorded as its short sha256, so the line never grows with the
inputs. Both carry ``inputs_sha256``, the hash of all the settings together, to tell at a
glance whether two files were made from the same inputs.
"""

from __future__ import annotations

import hashlib
import json
import platform
from collections.abc import Iterator
from contextlib import contextmanager
from contextvars import ContextVar
from datetime import UTC, datetime
from typing import Any

from metainterface._files import strict_json

#: Longest JSON text of one setting kept as is; longer ones are replaced by their hash.
MAX_INLINE = 200
#: Hex digits of the short hashes (64 bits: collisions are no concern for a record).
HASH_DIGITS = 16


#: The command line being run (its options as given), set by the CLI around its one library
#: call, so that the files written record it without a parameter threaded through the API.
_COMMAND: ContextVar[dict[str, Any] | None] = ContextVar("metainterface_command", default=None)


@contextmanager
def recording_command(options: dict[str, Any]) -> Iterator[None]:
    """Within this block, design files record ``options`` as the command that made them."""
    token = _COMMAND.set(options)
    try:
        yield
    finally:
        _COMMAND.reset(token)


def current_command() -> dict[str, Any] | None:
    """The command being run (see :func:`recording_command`), or None from Python."""
    return _COMMAND.get()


def short_hash(value: Any) -> str:
    """'sha256:<16 hex>' of a JSON-ready value (keys sorted, so dict order does not matter)."""
    text = json.dumps(value, sort_keys=True, default=str, separators=(",", ":"))
    return "sha256:" + hashlib.sha256(text.encode("utf-8")).hexdigest()[:HASH_DIGITS]


def _compact(value: Any) -> Any:
    text = json.dumps(value, sort_keys=True, default=str, separators=(",", ":"))
    return value if len(text) <= MAX_INLINE else short_hash(value)


def _torch_version() -> str:
    # imported here: the CLI's entry point imports this module before any work starts
    import torch

    return str(torch.__version__)


def provenance(*, stamp: bool = True, **settings: Any) -> dict[str, Any]:
    """A JSON-ready record: package, version, time, python, torch, the hash of all
    ``settings`` and the settings themselves.

    ``stamp=False`` leaves the creation time out, for files that must be byte-identical
    when made again with the same seed (the time then goes into a file beside them)."""
    from metainterface import __version__

    record = {
        "package": "metainterface",
        "version": __version__,
        "created": datetime.now(UTC).isoformat(timespec="seconds"),
        "python": platform.python_version(),
        "torch": _torch_version(),
        "inputs_sha256": short_hash(settings),
        "settings": settings,
    }
    if not stamp:
        del record["created"]
    return record


def compact_provenance(*, stamp: bool = True, **settings: Any) -> dict[str, Any]:
    """:func:`provenance` with each long setting replaced by its short hash."""
    record = provenance(stamp=stamp, **settings)
    record["settings"] = {k: _compact(v) for k, v in settings.items()}
    return record


def csv_header(*, stamp: bool = True, **settings: Any) -> str:
    """A '# ' comment line for CSV files (numpy and pandas(comment='#') skip it), its
    settings compacted (:func:`compact_provenance`)."""
    record = compact_provenance(stamp=stamp, **settings)
    return "# " + strict_json.dumps(record, sort_keys=True, default=str) + "\n"
