import os
import platform
import subprocess
import sys

import pytest

from metainterface.runtime import tune_allocator

# In a fresh process, malloc and free one 8 MiB block, then ask glibc (mallinfo2) how many
# freed bytes its heap still holds and how many bytes it has mapped outside the heap. By
# default a block that large is served by mmap and handed back to the kernel on free, so the
# heap keeps nothing; tuned, it comes from the heap and stays there for the next tensor.
# (The page faults this saves in training are measured by benchmarks/bench_train.py: they
# depend on the machine, so they are no test.)
SCRIPT = """
import ctypes, ctypes.util, sys
from metainterface.runtime import tune_allocator
if sys.argv[1] == "tuned":
    assert tune_allocator()
libc = ctypes.CDLL(ctypes.util.find_library("c") or "libc.so.6")
class MallInfo2(ctypes.Structure):
    _fields_ = [(name, ctypes.c_size_t) for name in (
        "arena", "ordblks", "smblks", "hblks", "hblkhd", "usmblks", "fsmblks",
        "uordblks", "fordblks", "keepcost")]
libc.mallinfo2.restype = MallInfo2
libc.malloc.restype = ctypes.c_void_p
libc.malloc.argtypes = (ctypes.c_size_t,)
libc.free.argtypes = (ctypes.c_void_p,)
before = libc.mallinfo2()
block = libc.malloc(8 << 20)
ctypes.memset(block, 1, 8 << 20)
mapped = libc.mallinfo2().hblkhd - before.hblkhd
libc.free(block)
print(mapped, libc.mallinfo2().fordblks - before.fordblks)
"""

glibc = pytest.mark.skipif(
    not sys.platform.startswith("linux")
    or platform.libc_ver()[0] != "glibc"
    or tuple(int(x) for x in platform.libc_ver()[1].split(".")[:2]) < (2, 33),
    reason="mallopt tuning is glibc-only; mallinfo2 needs glibc >= 2.33",
)


# environment variables that would change glibc's defaults in the child
_MALLOC_SETTINGS = ("MALLOC_", "GLIBC_TUNABLES")


def _heap_after_free(mode: str) -> tuple[int, int]:
    """(bytes the block mapped outside the heap, free bytes the heap gained by its free)."""
    out = subprocess.run(
        [sys.executable, "-c", SCRIPT, mode],
        env={k: v for k, v in os.environ.items() if not k.startswith(_MALLOC_SETTINGS)},
        capture_output=True,
        text=True,
        check=True,
    )
    mapped, kept = out.stdout.split()
    return int(mapped), int(kept)


@glibc
def test_tuned_allocator_keeps_freed_memory_in_the_heap():
    assert tune_allocator() is True
    assert tune_allocator() is True  # idempotent
    mapped, kept = _heap_after_free("default")
    assert mapped >= 8 << 20 and kept < 1 << 20  # glibc's default: mmap, returned on free
    mapped, kept = _heap_after_free("tuned")
    assert mapped == 0 and kept > 7 << 20  # tuned: heap (which held some free bytes), kept
