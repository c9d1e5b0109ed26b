"""Stream an uncompressed .npz to disk row block by row block, with flat memory.

``numpy.savez`` needs every array in memory at once. Here the shapes are declared up front,
so every array's place in the zip archive is known before any data exists: rows are written
straight to their final offsets as they arrive, the CRC-32 of each entry is accumulated on the
way, and the zip headers and central directory are written on ``close``. The result is an
ordinary ZIP64 archive of ``.npy`` entries, which ``numpy.load`` reads like any .npz.
"""

from __future__ import annotations

import io
import struct
import zlib
from collections.abc import Mapping
from typing import IO, Any

import numpy as np

_VERSION = 45  # ZIP64
_MADE_BY = (3 << 8) | _VERSION  # Unix
_DOS_DATE = (0 << 9) | (1 << 5) | 1  # 1980-01-01, as zipfile does for entries without a time
_FFFF, _FFFFFFFF = 0xFFFF, 0xFFFFFFFF
_LOCAL_EXTRA = 20  # ZIP64 extra in the local header: id, size, usize, csize
_CENTRAL_EXTRA = 28  # ZIP64 extra in the central header: id, size, usize, csize, offset


def _npy_header(shape: tuple[int, ...], dtype: np.dtype) -> bytes:
    buf = io.BytesIO()
    header = {
        "descr": np.lib.format.dtype_to_descr(dtype),
        "fortran_order": False,
        "shape": shape,
    }
    np.lib.format.write_array_header_1_0(buf, header)
    return buf.getvalue()


class _Entry:
    def __init__(self, name: str, shape: tuple[int, ...], dtype: np.dtype, offset: int) -> None:
        self.name = f"{name}.npy".encode("ascii")
        self.shape = shape
        self.dtype = dtype
        self.header_offset = offset
        npy = _npy_header(shape, dtype)
        self.data_offset = offset + 30 + len(self.name) + _LOCAL_EXTRA
        self.size = len(npy) + int(np.prod(shape, dtype=np.int64)) * dtype.itemsize
        self.end = self.data_offset + self.size
        self.npy = npy
        self.rows = 0  # rows written so far (axis 0; a 0-d array counts as 1 row)
        self.cursor = self.data_offset + len(npy)
        self.crc = zlib.crc32(npy)

    @property
    def total_rows(self) -> int:
        return self.shape[0] if self.shape else 1


class NpzStreamWriter:
    """Write named arrays of declared shapes into ``fh`` (binary, writable, seekable).

    specs: name -> (shape, dtype), in file order. ``write(name, rows)`` appends rows along
    axis 0 (for a 0-d array, pass the whole array once). ``close()`` checks that every array
    is complete and writes the archive's headers. Atomicity is the caller's business (open
    ``fh`` with ``metainterface._files.atomic_open``).
    """

    def __init__(self, fh: IO[bytes], specs: Mapping[str, tuple[tuple[int, ...], Any]]) -> None:
        self._fh = fh
        self._entries: dict[str, _Entry] = {}
        offset = 0
        for name, (shape, dtype) in specs.items():
            entry = _Entry(name, tuple(int(s) for s in shape), np.dtype(dtype), offset)
            self._entries[name] = entry
            offset = entry.end
        self._central_offset = offset
        for entry in self._entries.values():
            self._put(entry.data_offset, entry.npy)

    def _put(self, offset: int, data: Any) -> None:
        self._fh.seek(offset)
        self._fh.write(data)

    def write(self, name: str, rows: np.ndarray) -> None:
        """Append ``rows`` (shape (k, *shape[1:]), or the whole 0-d array) to array ``name``."""
        entry = self._entries[name]
        arr = np.asarray(rows, dtype=entry.dtype)
        if not arr.flags.c_contiguous:
            arr = arr.copy(order="C")
        if entry.shape:
            if arr.shape[1:] != entry.shape[1:] or entry.rows + arr.shape[0] > entry.shape[0]:
                raise ValueError(
                    f"{name}: rows of shape {arr.shape} do not fit {entry.shape} "
                    f"after {entry.rows} rows"
                )
            k = arr.shape[0]
        else:
            if arr.shape != () or entry.rows:
                raise ValueError(f"{name}: a 0-d array is written once, whole")
            k = 1
        data = arr.reshape(-1).view(np.uint8)
        self._put(entry.cursor, data)
        entry.crc = zlib.crc32(data, entry.crc)
        entry.cursor += len(data)
        entry.rows += k

    def close(self) -> None:
        """Write the zip headers and central directory; every array must be complete."""
        for entry in self._entries.values():
            if entry.rows != entry.total_rows:
                raise ValueError(f"{entry.name.decode()}: {entry.rows} of {entry.total_rows} rows")
        central = bytearray()
        for e in self._entries.values():
            local = struct.pack(
                "<IHHHHHIIIHH",
                0x04034B50,
                _VERSION,
                0,
                0,
                0,
                _DOS_DATE,
                e.crc,
                _FFFFFFFF,
                _FFFFFFFF,
                len(e.name),
                _LOCAL_EXTRA,
            )
            local += e.name + struct.pack("<HHQQ", 0x0001, 16, e.size, e.size)
            self._put(e.header_offset, local)
            central += struct.pack(
                "<IHHHHHHIIIHHHHHII",
                0x02014B50,
                _MADE_BY,
                _VERSION,
                0,
                0,
                0,
                _DOS_DATE,
                e.crc,
                _FFFFFFFF,
                _FFFFFFFF,
                len(e.name),
                _CENTRAL_EXTRA,
                0,
                0,
                0,
                0o100644 << 16,  # regular file, rw-r--r--
                _FFFFFFFF,
            )
            central += e.name + struct.pack("<HHQQQ", 0x0001, 24, e.size, e.size, e.header_offset)
        n = len(self._entries)
        end64 = self._central_offset + len(central)
        tail = struct.pack(
            "<IQHHIIQQQQ",
            0x06064B50,
            44,
            _MADE_BY,
            _VERSION,
            0,
            0,
            n,
            n,
            len(central),
            self._central_offset,
        )
        tail += struct.pack("<IIQI", 0x07064B50, 0, end64, 1)
        tail += struct.pack("<IHHHHIIH", 0x06054B50, 0, 0, _FFFF, _FFFF, _FFFFFFFF, _FFFFFFFF, 0)
        self._put(self._central_offset, bytes(central) + tail)
        self._fh.flush()
