"""Joining a Dask cluster (the ``distributed`` extra): an executor for BEM sweeps.

The library runs on any ``concurrent.futures.Executor``; this module only turns a scheduler
address, or ``"local"``, into one: ``dask.distributed.Client(...).get_executor()``. Dask is
imported here, when a scheduler is asked for, never at ``import metainterface``.
"""

from __future__ import annotations

import contextlib
from collections.abc import Iterator
from concurrent.futures import Executor
from types import ModuleType

from metainterface.errors import MetainterfaceError

DASK_HINT = "pip install 'metainterface[distributed]'"
#: Seconds to wait for a scheduler to answer.
CONNECT_TIMEOUT = 30


def require_dask() -> ModuleType:
    """Import ``dask.distributed``, or raise a one-line error with the install command."""
    try:
        import dask.distributed as distributed
    except ImportError:
        raise MetainterfaceError(
            f"--scheduler needs Dask, which is not installed: run `{DASK_HINT}`"
        ) from None
    return distributed


def check_scheduler(scheduler: str) -> str:
    """``"local"`` or a scheduler address such as ``tcp://host:8786``, with Dask installed
    (checked before any work starts)."""
    if not isinstance(scheduler, str) or not (scheduler == "local" or "://" in scheduler):
        raise MetainterfaceError(
            f"scheduler must be 'local' or an address like tcp://HOST:PORT, got {scheduler!r}"
        )
    require_dask()
    return scheduler


@contextlib.contextmanager
def dask_executor(scheduler: str, workers: int | None = None) -> Iterator[Executor]:
    """An executor on a Dask cluster, closed on exit.

    scheduler: ``"local"`` starts a ``LocalCluster`` of ``workers`` processes (one thread
    each: Tamaas holds the GIL) and stops it on exit; an address (``tcp://HOST:PORT``) joins
    a running cluster, which is left running. The client is not made Dask's default, so the
    caller's own Dask settings are left as they were.
    """
    check_scheduler(scheduler)
    distributed = require_dask()
    cluster = None
    try:
        if scheduler == "local":
            cluster = distributed.LocalCluster(
                n_workers=workers,
                threads_per_worker=1,
                processes=True,
                dashboard_address=None,
            )
            client = distributed.Client(cluster, set_as_default=False)
        else:
            client = distributed.Client(scheduler, timeout=CONNECT_TIMEOUT, set_as_default=False)
    except (OSError, TimeoutError) as exc:
        if cluster is not None:
            cluster.close()
        raise MetainterfaceError(
            f"cannot reach the Dask scheduler at {scheduler}: {exc}".splitlines()[0]
        ) from None
    try:
        yield client.get_executor(pure=False)
    finally:
        client.close()
        if cluster is not None:
            cluster.close()
