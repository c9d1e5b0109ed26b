"""The contact solvers a BEM validation can run on: one registry, looked up by name.

``torch`` (the default): our own Polonsky-Keer-Rey solver (``torch_bem``), float64 on CPU
threads or a CUDA device; it needs nothing beyond the base install. ``tamaas``: Tamaas's
``PolonskyKeerRey`` (the ``bem`` extra, Linux x86_64 wheels only), the reference the torch
engine is tested against. Both measure convergence the same way, so one tolerance means the
same for both, and both return a ``bem.LoadPath``.
"""

from __future__ import annotations

import contextlib
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from typing import Any, ClassVar, Protocol

import numpy as np

from metainterface._names import DEFAULT_ENGINE
from metainterface.errors import MetainterfaceError
from metainterface.validation.loadpath import (
    MAX_ITER,
    TOLERANCE,
    LoadPath,
    PathRecorder,
    require_tamaas,
    tamaas_path,
)


@contextlib.contextmanager
def torch_threads(threads: int | None) -> Iterator[None]:
    """torch on ``threads`` intra-op threads for the block, then as it was (None: as is).

    A process forked after its parent used torch's OpenMP threads hangs in its first torch
    operation on several threads, so solves in worker processes run on one.
    """
    if threads is None:
        yield
        return
    import torch

    before = torch.get_num_threads()
    torch.set_num_threads(int(threads))
    try:
        yield
    finally:
        torch.set_num_threads(before)


class Engine(Protocol):
    """A contact solver: the load path of one periodic cell."""

    name: str
    solver: str  # how the results were made, in words (recorded with them)

    def check(self, device: Any = "auto") -> None:
        """Raise a one-line MetainterfaceError if this engine cannot run on ``device``."""

    def solve_path(
        self,
        heights: np.ndarray,
        cell_side: float,
        loads: np.ndarray,
        owner: np.ndarray,
        n_asperities: int,
        *,
        tolerance: float = TOLERANCE,
        max_iter: int = MAX_ITER,
        first_index: int = 0,
        total: int | None = None,
        report: Callable[[int], Any] | None = None,
        fields: bool = False,
        device: Any = "auto",
        threads: int | None = None,
        contact_depth: np.ndarray | None = None,
    ) -> LoadPath:
        """As ``bem.solve_path``."""


@dataclass(frozen=True)
class TamaasEngine:
    """Tamaas's PolonskyKeerRey on one CPU thread (the ``bem`` extra)."""

    name: ClassVar[str] = "tamaas"
    solver: ClassVar[str] = "tamaas PolonskyKeerRey, basic_2d, E* = 1"

    def check(self, device: Any = "auto") -> None:
        require_tamaas()
        text = str(device).strip().lower()
        if text.startswith("cuda"):
            raise MetainterfaceError(
                f"engine='tamaas' runs on the CPU only, got device={device!r} "
                "(use engine='torch' for a GPU)",
                argument="device",
            )

    def solve_path(
        self,
        *args: Any,
        device: Any = "auto",
        threads: int | None = None,
        contact_depth: np.ndarray | None = None,  # Tamaas starts from its own guess
        **kw: Any,
    ) -> LoadPath:
        self.check(device)
        return tamaas_path(*args, **kw)


@dataclass(frozen=True)
class TorchEngine:
    """Our Polonsky-Keer-Rey solver in torch (``torch_bem``), float64, CPU or CUDA."""

    name: ClassVar[str] = "torch"
    solver: ClassVar[str] = "metainterface torch Polonsky-Keer-Rey (float64), E* = 1"

    def check(self, device: Any = "auto") -> None:
        from metainterface._device import resolve_device

        resolve_device(device)

    def solve_path(
        self,
        heights: np.ndarray,
        cell_side: float,
        loads: np.ndarray,
        owner: np.ndarray,
        n_asperities: int,
        *,
        tolerance: float = TOLERANCE,
        max_iter: int = MAX_ITER,
        first_index: int = 0,
        total: int | None = None,
        report: Callable[[int], Any] | None = None,
        fields: bool = False,
        device: Any = "auto",
        threads: int | None = None,
        contact_depth: np.ndarray | None = None,
    ) -> LoadPath:
        from metainterface._device import resolve_device
        from metainterface.validation import torch_bem

        dev = resolve_device(device)
        loads = np.asarray(loads, dtype=np.float64)
        total = len(loads) if total is None else total
        rec = PathRecorder(len(loads), np.asarray(heights).shape[0], owner, n_asperities, fields)

        def on_load(i: int, pressure: np.ndarray, gap: np.ndarray, err: float, sec: float):
            torch_bem.check_converged(err, tolerance, max_iter, first_index + i, total, loads[i])
            rec.record(i, pressure, gap, err, sec)
            if report is not None:
                report(1)

        with torch_threads(threads):
            start = None
            if contact_depth is not None:
                start = torch_bem.contact_start(heights, owner, contact_depth)
            try:
                torch_bem.solve_path(
                    heights,
                    cell_side,
                    loads,
                    device=dev,
                    tolerance=tolerance,
                    max_iter=max_iter,
                    on_load=on_load,
                    start=start,
                )
            except ArithmeticError as exc:
                i, why = exc.args
                raise MetainterfaceError(
                    f"BEM failed at load {first_index + i + 1} of {total} "
                    f"(P* = {loads[i]:.6g}): {why} (try a finer grid)"
                ) from None
        return rec.path()


#: The engines by name (``_names.ENGINE_NAMES`` spells them for the command line).
ENGINES: dict[str, Engine] = {"torch": TorchEngine(), "tamaas": TamaasEngine()}


def get_engine(engine: str | Engine | None = None) -> Engine:
    """The engine named ``engine`` (None: the default, torch), or a one-line error."""
    if engine is None:
        engine = DEFAULT_ENGINE
    if not isinstance(engine, str):
        if hasattr(engine, "solve_path") and hasattr(engine, "name"):
            return engine
        raise MetainterfaceError(f"engine must be one of {', '.join(ENGINES)}, got {engine!r}")
    found = ENGINES.get(engine.strip().lower())
    if found is None:
        raise MetainterfaceError(
            f"engine must be one of {', '.join(ENGINES)}, got {engine!r}", argument="engine"
        )
    return found


def check_engine(engine: str | Engine | None, device: Any = "auto") -> Engine:
    """``get_engine`` and its ``check``: a one-line error now (Tamaas not installed, a device
    torch does not see) rather than in a worker."""
    found = get_engine(engine)
    found.check(device)
    return found
