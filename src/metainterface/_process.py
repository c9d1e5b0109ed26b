"""Worker processes that never outlive their parent.

A pool's workers are ordinary children: if the parent is killed outright (SIGKILL, the OOM
killer), nothing tells them to stop and they run on, holding cores and memory. On Linux the
kernel can send a signal to a child when its parent dies (prctl PR_SET_PDEATHSIG), which
:func:`die_with_parent` asks for; call it first thing in a pool's worker initializer.
Elsewhere it watches the parent from a daemon thread instead.
"""

from __future__ import annotations

import ctypes
import ctypes.util
import os
import signal
import sys
import threading
import time

_PR_SET_PDEATHSIG = 1


def die_with_parent(parent: int | None = None) -> None:
    """Make this process end (SIGKILL) when its parent process ends.

    ``parent``: the pid the worker was started by (default: the current parent). If the
    parent is already gone when this runs, the process exits at once.
    """
    parent = os.getppid() if parent is None else parent
    if sys.platform.startswith("linux"):
        try:
            libc = ctypes.CDLL(ctypes.util.find_library("c") or "libc.so.6", use_errno=True)
            if libc.prctl(_PR_SET_PDEATHSIG, signal.SIGKILL, 0, 0, 0) == 0:
                if os.getppid() != parent:  # the parent died before the request took hold
                    os._exit(1)
                return
        except (OSError, AttributeError):  # pragma: no cover - no usable libc
            pass
    threading.Thread(target=_watch, args=(parent,), daemon=True).start()  # pragma: no cover


def _watch(parent: int) -> None:  # pragma: no cover - non-Linux fallback
    while os.getppid() == parent:
        time.sleep(1.0)
    os._exit(1)
