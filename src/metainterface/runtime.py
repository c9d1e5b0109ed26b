"""Process-level tuning for the many short-lived megabyte tensors of the physics layer.

glibc hands every freed block above its mmap threshold (128 KiB at first, adapting up to
32 MiB) back to the kernel, and the next allocation of that size page-faults it in again,
zero-filled. A training step of the surrogate allocates ~60 such (batch, N, K) temporaries:
measured here, an epoch took ~400,000 minor page faults and about a quarter of its time
went to them; 100,000 exact curves took 2.7 s instead of 1.2 s. Keeping freed memory in the
heap removes them; the price is that the process keeps its peak heap (a few hundred MB for
training) until it exits. The CLI, ``train``, ``design`` and ``curves_numpy`` (so dataset
generation) call :func:`tune_allocator`.
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
