"""Process-level tuning for the many short-lived megabyte tensors of the physics layer.

glibc hands every freed block above its mmap threshold (128 KiB at first, adapting up to
32 MiB) back to the kernel, and the next allocation of that size page-faults it in again,
zero-filled; a training step allocates dozens of such temporaries. Keeping freed memory in
the heap removes those faults (``benchmarks/bench_train.py`` reports them); the price is
that the process keeps its peak heap until it exits. So it is a decision for the process,
made at entry points: the CLI and the benchmarks call :func:`tune_allocator`, a notebook
user may call ``metainterface.tune_allocator()``; no library function does.
"""

from __future__ import annotations

import ctypes
import ctypes.util
import sys

# mallopt parameters (malloc.h)
_M_TRIM_THRESHOLD = -1
_M_MMAP_THRESHOLD = -3

_MMAP_THRESHOLD = 32 << 20  # glibc's upper limit on 64-bit
_TRIM_THRESHOLD = 1 << 30

_tuned: bool | None = None


def tune_allocator() -> bool:
    """Make glibc keep freed tensor memory for reuse (idempotent; a no-op off glibc).

    Returns True if the allocator was tuned (now or by an earlier call).
    """
    global _tuned
    if _tuned is not None:
        return _tuned
    _tuned = False
    if not sys.platform.startswith("linux"):
        return False
    try:
        libc = ctypes.CDLL(ctypes.util.find_library("c") or "libc.so.6")
        mallopt = libc.mallopt
    except (OSError, AttributeError):  # musl or another libc without mallopt
        return False
    mallopt.argtypes = (ctypes.c_int, ctypes.c_int)
    mallopt.restype = ctypes.c_int
    _tuned = all(
        mallopt(param, value) == 1
        for param, value in (
            (_M_MMAP_THRESHOLD, _MMAP_THRESHOLD),
            (_M_TRIM_THRESHOLD, _TRIM_THRESHOLD),
        )
    )
    return _tuned
