"""Atomic file output: write to a temporary file beside the target, then rename.

A run that is interrupted never leaves a half-written file under the final name, and the
files of one command are written as a set (:func:`output_set`): all of them or none.

Temporaries are named ``.NAME.mi-PID-RANDOM.tmp`` beside their target. They are removed on
any exception (SIGINT, and SIGTERM once :func:`terminate_as_interrupt` is installed); a
process killed outright (SIGKILL) cannot clean up, so every later write into the same folder
removes the temporaries of processes that no longer exist (:func:`sweep_stale`).

An interrupt can land between any two bytecodes, so each temporary's name is recorded
before the file is made (an interrupt in between leaves nothing to find), and a set's
renames run with SIGINT/SIGTERM/SIGHUP held back (:func:`_held_interrupts`): the set goes out
whole and the interrupt is raised after.

Only regular files are ever replaced: a symlink, FIFO, device or folder under the target's
name is refused with a one-line error, so ``--out /dev/stdout`` cannot clobber anything.
"""

from __future__ import annotations

import contextlib
import os
import re
import secrets
import shutil
import signal
import stat
import threading
from collections.abc import Iterator
from pathlib import Path
from typing import IO, Any

from metainterface.errors import MetainterfaceError

_TMP = re.compile(r"^\..+\.mi-(\d+)-[A-Za-z0-9_]+\.tmp$")


def _alive(pid: int) -> bool:
    if pid == os.getpid():
        return True
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # someone else's live process
        return True
    return True


def sweep_stale(folder: str | os.PathLike[str]) -> list[Path]:
    """Remove the temporaries that dead processes left in ``folder``; returns what went."""
    gone = []
    with contextlib.suppress(OSError):
        for entry in os.scandir(folder):
            m = _TMP.match(entry.name)
            if m is None or _alive(int(m.group(1))):
                continue
            with contextlib.suppress(OSError):
                if entry.is_dir(follow_symlinks=False):
                    shutil.rmtree(entry.path)
                else:
                    os.unlink(entry.path)
                gone.append(Path(entry.path))
    return gone


def _kind(mode: int) -> str:
    for test, word in (
        (stat.S_ISLNK, "a symbolic link"),
        (stat.S_ISFIFO, "a FIFO"),
        (stat.S_ISCHR, "a character device"),
        (stat.S_ISBLK, "a block device"),
        (stat.S_ISSOCK, "a socket"),
        (stat.S_ISDIR, "a folder"),
    ):
        if test(mode):
            return word
    return "a regular file" if stat.S_ISREG(mode) else "not a regular file"


def check_output_file(path: str | os.PathLike[str]) -> Path:
    """``path`` is a usable output file name: not empty, nothing but a regular file (or
    nothing) under that name, and no ancestor that is a file. One-line errors."""
    if isinstance(path, str | os.PathLike) and not os.fspath(path):
        raise MetainterfaceError("output path is empty; give a file name")
    path = Path(path)
    if "\0" in str(path):
        raise MetainterfaceError(f"output path {str(path)!r} contains a NUL character")
    mode = _mode(path, follow=False)  # a symlink itself is not a regular file
    if mode is not None and not stat.S_ISREG(mode):
        raise MetainterfaceError(
            f"refusing to replace {path}: it is {_kind(mode)}, only regular files are replaced"
        )
    return path


def _mode(path: Path, *, follow: bool) -> int | None:
    """The file mode of ``path`` (None: nothing there); one-line errors for the rest."""
    try:
        return (os.stat if follow else os.lstat)(path).st_mode
    except FileNotFoundError:
        return None
    except NotADirectoryError:
        raise MetainterfaceError(f"cannot write {path}: {_file_ancestor(path)} is a file") from None
    except OSError as exc:
        raise MetainterfaceError(f"cannot write {path}: {exc.strerror}") from None


def check_output_folder(path: str | os.PathLike[str]) -> Path:
    """``path`` is a usable output folder: not empty, a folder or nothing, no file above it."""
    if isinstance(path, str | os.PathLike) and not os.fspath(path):
        raise MetainterfaceError("output folder is empty; give a folder name")
    path = Path(path)
    mode = _mode(path, follow=True)
    if mode is not None and not stat.S_ISDIR(mode):
        raise MetainterfaceError(f"output folder {path} is {_kind(mode)}, expected a folder")
    if mode is None:
        ancestor = _file_ancestor(path)
        if ancestor is not None:
            raise MetainterfaceError(f"cannot create folder {path}: {ancestor} is a file")
    return path


def _file_ancestor(path: Path) -> Path | None:
    """The first existing ancestor of ``path`` that is not a folder, if any."""
    for parent in reversed(path.parents):
        try:
            if not stat.S_ISDIR(os.stat(parent).st_mode):
                return parent
        except FileNotFoundError:
            return None
        except OSError:
            return parent
    return None


def _raise_interrupt(signum: int, frame: Any) -> None:
    raise KeyboardInterrupt(signal.Signals(signum).name)


_HELD = (signal.SIGINT, signal.SIGTERM, getattr(signal, "SIGHUP", signal.SIGTERM))


@contextlib.contextmanager
def _held_interrupts() -> Iterator[None]:
    """Inside the block, a signal that would raise KeyboardInterrupt (SIGINT's default
    handler, :func:`terminate_as_interrupt`'s) is held back and raised when the block ends;
    signals with any other handler are left alone. Main thread only (others never see them)."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    pending: list[str] = []

    def hold(signum: int, frame: Any) -> None:
        pending.append(signal.Signals(signum).name)

    previous = {}
    try:
        for sig in dict.fromkeys(_HELD):
            old = signal.getsignal(sig)
            if old is signal.default_int_handler or old is _raise_interrupt:
                previous[sig] = old
                signal.signal(sig, hold)
        yield
    finally:
        for sig, old in previous.items():
            signal.signal(sig, old)
    if pending:
        raise KeyboardInterrupt(pending[0])


class _Set:
    """Temporaries written so far, each with its final name; every temporary made (named
    before it is made), and folders made for them."""

    def __init__(self) -> None:
        self.staged: dict[Path, str] = {}
        self.temps: list[str] = []
        self.made: list[Path] = []

    def commit(self) -> None:
        with _held_interrupts():  # every rename, or (before the first) none
            for path, tmp in self.staged.items():
                os.replace(tmp, path)
            self.staged.clear()
        self._remove_temps()  # files written twice: the earlier ones

    def _remove_temps(self) -> None:
        for tmp in self.temps:
            with contextlib.suppress(FileNotFoundError):
                os.unlink(tmp)
        self.temps.clear()

    def rollback(self) -> None:
        self.staged.clear()
        self._remove_temps()
        for folder in reversed(self.made):  # only folders this set made, only when empty
            with contextlib.suppress(OSError):
                folder.rmdir()


_local = threading.local()


@contextlib.contextmanager
def output_set() -> Iterator[None]:
    """Files written inside go out together: renamed into place when the block ends, or all
    removed (with the folders made for them) if it raises. Nested sets join the outer one.

    Usable as a decorator. A file read back inside the block is not there yet.
    """
    if getattr(_local, "set", None) is not None:
        yield
        return
    _local.set = current = _Set()
    try:
        yield
        current.commit()
    except BaseException:
        current.rollback()
        raise
    finally:
        _local.set = None


def ensure_parent(path: str | os.PathLike[str]) -> Path:
    """Create the folder of ``path`` if needed; a one-line error if that is impossible."""
    path = check_output_file(path)
    parent = path.parent
    missing = [p for p in (parent, *parent.parents) if not p.exists()]
    try:
        parent.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise MetainterfaceError(f"cannot create folder {parent}: {exc.strerror}") from None
    current = getattr(_local, "set", None)
    if current is not None:
        current.made.extend(reversed(missing))
    return path


def _temporary(path: Path) -> str:
    """A fresh temporary's name beside ``path`` (made by :func:`_create`)."""
    return os.path.join(path.parent, f".{path.name}.mi-{os.getpid()}-{secrets.token_hex(8)}.tmp")


def _create(tmp: str, path: Path) -> int:
    """Make the temporary ``tmp`` (only if new) and open it for writing; mode 0666 less the
    umask, as ``open`` makes files."""
    flags = os.O_WRONLY | os.O_CREAT | os.O_EXCL | getattr(os, "O_CLOEXEC", 0)
    try:
        return os.open(tmp, flags, 0o666)
    except OSError as exc:
        raise MetainterfaceError(f"cannot write {path}: {exc.strerror}") from None


@contextlib.contextmanager
def atomic_open(path: str | os.PathLike[str], mode: str = "w", **kwargs: Any) -> Iterator[IO[Any]]:
    """Open a temporary file for writing; on success it replaces ``path`` in one rename
    (at the end of the enclosing :func:`output_set`, if any)."""
    with output_set():
        path = ensure_parent(path)
        sweep_stale(path.parent)
        current: _Set = _local.set
        tmp = _temporary(path)
        current.temps.append(tmp)  # before the file exists: the set removes it on any error
        fd = _create(tmp, path)
        current.staged[path] = tmp  # written twice in one set: the later one wins
        try:
            with os.fdopen(fd, mode, **kwargs) as fh:
                yield fh
                fh.flush()
                os.fsync(fh.fileno())
            check_output_file(path)  # still nothing but a regular file there
        except BaseException:  # never commit a half-written file, even if the caller goes on
            current.staged.pop(path, None)
            with contextlib.suppress(FileNotFoundError):
                os.unlink(tmp)
            raise


@contextlib.contextmanager
def atomic_path(path: str | os.PathLike[str]) -> Iterator[Path]:
    """A temporary path beside ``path`` for a library that writes by file name; on success
    it replaces ``path`` in one rename."""
    path = ensure_parent(path)
    tmp = _temporary(path)
    try:  # from before the file exists, so that an interrupt cannot leave it behind
        os.close(_create(tmp, path))
        yield Path(tmp)
        os.replace(tmp, path)
    except BaseException:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(tmp)
        raise


def write_text(path: str | os.PathLike[str], text: str) -> Path:
    """Atomically write a text file (UTF-8)."""
    with atomic_open(path, "w", encoding="utf-8", newline="\n") as fh:
        fh.write(text)
    return Path(path)


def write_bytes(path: str | os.PathLike[str], data: bytes) -> Path:
    """Atomically write a binary file."""
    with atomic_open(path, "wb") as fh:
        fh.write(data)
    return Path(path)


@contextlib.contextmanager
def terminate_as_interrupt() -> Iterator[None]:
    """Inside the block, SIGTERM and SIGHUP raise KeyboardInterrupt in the main thread, as
    SIGINT does, so that every temporary is removed on the way out; the previous handlers
    come back after. For entry points (the command line)."""

    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = {
        sig: signal.signal(sig, _raise_interrupt) for sig in (signal.SIGTERM, signal.SIGHUP)
    }
    try:
        yield
    finally:
        for sig, old in previous.items():
            signal.signal(sig, old)
