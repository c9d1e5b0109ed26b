"""torch's CPU threads: sized to the work, and never left spinning on a busy machine.

torch runs its CPU kernels on OpenMP threads (GNU libgomp in the pip wheels) that, by default,
spin for a while at every barrier instead of sleeping. When another process holds a core, one
of them is descheduled and the others spin until it comes back, at every one of the thousands
of small parallel regions a design or a BEM solve runs: measured on a 2-core machine with two
busy processes beside it, a design took 10x and a BEM check 18x as long as on one thread
(``benchmarks/bench_loaded.py``, ``docs/concepts/devices.md``). So:

* ``import metainterface`` asks libgomp to sleep while it waits (``OMP_WAIT_POLICY=PASSIVE``)
  when torch is not loaded yet and the user set no policy; libgomp reads it once, when torch
  loads. Worker processes inherit it.
* Each public entry point runs its torch work on as many threads as that work gains from:
  ``"light"`` work (designs, refinements, curves, BEM checks, tolerance studies: thousands of
  kernels of microseconds each) on one, which was as fast as two on an idle machine; its
  parallelism comes from processes (``jobs=``, ``--workers``). ``"heavy"`` work (training,
  datasets: large batched kernels) on all of torch's threads, and on one if torch's threads
  would spin (torch was loaded before us with no wait policy).
* A user's own choice always wins: :func:`set_threads`, ``OMP_NUM_THREADS`` (or
  ``MKL_NUM_THREADS``) in the environment, or a ``torch.set_num_threads`` call. Where that
  choice puts several spinning threads to work (torch loaded first, no policy set), a warning
  says so once, with what to do.
"""

from __future__ import annotations

import contextlib
import functools
import os
import sys
import threading
import warnings
from collections.abc import Callable, Iterator
from typing import Any, Generic, Literal, TypeVar

#: The environment variables through which a user chooses torch's thread count.
USER_ENV = ("OMP_NUM_THREADS", "MKL_NUM_THREADS")
#: libgomp's wait policy, read once when torch (and so libgomp) loads.
WAIT_ENV = "OMP_WAIT_POLICY"
#: Most threads set_threads accepts (a slip, not a machine, beyond it).
MAX_THREADS = 4096

Work = Literal["light", "heavy"]
F = TypeVar("F", bound=Callable[..., Any])


class ThreadWarning(UserWarning):
    """torch's threads will spin while they wait (torch was loaded before metainterface)."""


class _State:
    chosen: int | None = None  # set_threads
    torch_first: bool = False  # torch was loaded before metainterface
    passive: bool = False  # libgomp sleeps while it waits (set by us or by the user)
    baseline: int | None = None  # torch's own thread count, as first seen
    warned: bool = False


_state = _State()
_local = threading.local()  # the counts our blocks set, innermost last


def prepare_process() -> None:
    """Called once when the package is imported: ask for a passive wait policy while it can
    still take effect (before torch loads), unless the user chose one."""
    _state.torch_first = "torch" in sys.modules
    policy = os.environ.get(WAIT_ENV, "").strip()
    if not _state.torch_first and not policy:
        os.environ[WAIT_ENV] = "PASSIVE"
        policy = "PASSIVE"
    _state.passive = policy.upper() == "PASSIVE"
    if _state.torch_first:  # the count torch has now is the one to leave alone, if changed
        _state.baseline = sys.modules["torch"].get_num_threads()


def set_threads(threads: int | None) -> None:
    """Run metainterface's torch work on ``threads`` CPU threads (None: chosen per task).

    By default each call picks the count its work gains from (one for designs, BEM checks
    and curves, whose thousands of small kernels gain nothing from more; all of torch's for
    training and datasets) and puts torch back as it was afterwards. A count set here, in
    ``OMP_NUM_THREADS``, or with ``torch.set_num_threads`` is used instead, for every call.
    Processes (``jobs=``, ``--workers``) are the way to use more cores for BEM work.
    """
    if threads is not None:
        from metainterface import _checks

        threads = _checks.whole("threads", threads, low=1, high=MAX_THREADS)
    _state.chosen = threads


def _stack() -> list[int]:
    stack = getattr(_local, "stack", None)
    if stack is None:
        stack = _local.stack = []
    return stack


def _choose(work: Work, torch: Any) -> int | None:
    """The count for ``work``, or None where the user's setting is to stay as it is."""
    if _state.chosen is not None:
        return _state.chosen
    if any(os.environ.get(name, "").strip() for name in USER_ENV):
        return None
    now = torch.get_num_threads()
    stack = _stack()
    if stack:
        if now != stack[-1]:  # changed by the user inside one of our calls
            return None
    elif _state.baseline is None:
        _state.baseline = now
    elif now != _state.baseline:  # torch.set_num_threads by the user
        return None
    if work == "light":
        return 1
    return _state.baseline if _state.passive else 1


def _warn_spinning(count: int) -> None:
    if count > 1 and not _state.passive and _state.torch_first and not _state.warned:
        _state.warned = True
        warnings.warn(
            f"torch was imported before metainterface, so its {count} CPU threads spin while "
            f"they wait and run many times slower when other processes use the cores; set "
            f"{WAIT_ENV}=PASSIVE before starting Python, or import metainterface first",
            ThreadWarning,
            stacklevel=4,
        )


@contextlib.contextmanager
def threads_for(work: Work = "light") -> Iterator[int]:
    """torch on the thread count chosen for ``work`` inside the block, then as it was.
    Yields the count in use."""
    import torch

    chosen = _choose(work, torch)
    before = torch.get_num_threads()
    count = before if chosen is None else chosen
    _warn_spinning(count)
    if count != before:
        torch.set_num_threads(count)
    stack = _stack()
    stack.append(count)
    try:
        yield count
    finally:
        stack.pop()
        if count != before:
            torch.set_num_threads(before)


def uses_threads(work: Work = "light") -> Callable[[F], F]:
    """Decorate a public entry point: its torch work runs inside ``threads_for(work)``."""

    def wrap(fn: F) -> F:
        @functools.wraps(fn)
        def run(*args: Any, **kwargs: Any) -> Any:
            with threads_for(work):
                return fn(*args, **kwargs)

        return run  # type: ignore[return-value]

    return wrap


T = TypeVar("T")

_stops = threading.local()


class _Stop:
    """A request to stop: this thread's own, or that of the thread that started it."""

    def __init__(self, parent: _Stop | None) -> None:
        self.event = threading.Event()
        self.parent = parent

    def is_set(self) -> bool:
        return self.event.is_set() or (self.parent is not None and self.parent.is_set())


def stop_asked() -> bool:
    """Whether the work on this thread is no longer wanted: the caller of its
    :func:`in_background` (or theirs) gave up on it. Loops of long steps end early on it."""
    stop = getattr(_stops, "stop", None)
    return stop is not None and stop.is_set()


class Background(Generic[T]):
    """``fn()`` running on a daemon thread (:func:`in_background`). Call it for the result
    (or its error); :meth:`stop` says it is no longer wanted (:func:`stop_asked` on that
    thread and the threads it starts). As a context manager, leaving the block by an error
    (an interrupt too) stops it."""

    def __init__(self, fn: Callable[[], T], name: str) -> None:
        self._out: dict[str, Any] = {}
        self._stop = _Stop(getattr(_stops, "stop", None))
        self._thread = threading.Thread(target=self._run, args=(fn,), name=name, daemon=True)
        self._thread.start()

    def _run(self, fn: Callable[[], T]) -> None:
        _stops.stop = self._stop
        try:
            self._out["result"] = fn()
        except BaseException as exc:  # handed to the caller, which raises it
            self._out["error"] = exc

    def stop(self) -> None:
        self._stop.event.set()

    def __call__(self) -> T:
        try:
            self._thread.join()
        except BaseException:  # an interrupt while waiting: the work is not wanted
            self.stop()
            raise
        if "error" in self._out:
            raise self._out["error"]
        return self._out["result"]

    def __enter__(self) -> Background[T]:
        return self

    def __exit__(self, kind: type[BaseException] | None, *rest: Any) -> None:
        if kind is not None:
            self.stop()
            # and wait for it to end at its next stop_asked() (one step): a process that
            # exits while a daemon thread is inside torch aborts ("terminate called without
            # an active exception", status 134) instead of exiting with its own status
            self._thread.join()


def in_background(fn: Callable[[], T], name: str) -> Background[T]:
    """``fn()`` started on a daemon thread ``name``; the returned call waits for its result
    (or raises its error). For torch work that releases the GIL (FFTs, conjugate-gradient
    steps) beside the caller's own. A daemon, so that an interrupt of the caller (Ctrl-C)
    need not wait for the whole work, as a pool's worker's would; used as a context manager,
    the block left by an error stops the work and waits for it to end at its next
    :func:`stop_asked`, so that the process exits with its own status."""
    return Background(fn, name)
