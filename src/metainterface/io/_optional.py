"""Optional export libraries, imported where the export starts."""

from __future__ import annotations

from typing import Any

from metainterface.errors import MetainterfaceError


def require(module: str, what: str) -> Any:
    """Import an optional export library, or a one-line error with the install command."""
    import importlib

    try:
        return importlib.import_module(module)
    except ImportError:
        raise MetainterfaceError(
            f"{what} export needs {module}, which is not installed: run "
            "`pip install 'metainterface[export]'`"
        ) from None
