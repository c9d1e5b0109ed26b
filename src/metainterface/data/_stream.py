"""A dataset's curves computed chunk by chunk on threads side by side, and streamed into its
.npz in order as they come in (memory stays bounded), refused where not finite."""

from __future__ import annotations

import contextlib
from collections import deque
from collections.abc import Iterator, Mapping
from concurrent.futures import Future, ThreadPoolExecutor
from typing import Any

import numpy as np
import torch

from metainterface.data.categories import CATEGORIES, CATEGORY_NAMES
from metainterface.data.load import CURVE_ARRAYS, SPLITS
from metainterface.data.npz import NpzStreamWriter
from metainterface.errors import MetainterfaceError
from metainterface.physics.cell import CellSettings
from metainterface.physics.curves import curves_numpy

_CURVE_CHUNK = 256  # curves_numpy's inner chunk: small temporaries keep the peak RSS low


class Stream:
    """The dataset's arrays streamed into an open .npz as the curves of each chunk come in
    (designs, category and split names, curves), with the test rows kept for figures."""

    def __init__(
        self, settings: CellSettings, labels: np.ndarray, specs: dict, examples: int
    ) -> None:
        self.settings, self.labels, self.specs, self.examples = settings, labels, specs, examples
        self.cat_names = np.array(CATEGORY_NAMES, dtype=specs["category"][1])
        self.split_names = np.array(SPLITS, dtype=specs["split"][1])
        self.kept: dict[int, list[dict[str, np.ndarray]]] = {c: [] for c in range(len(CATEGORIES))}
        self.pos = 0

    def write(
        self,
        fh: Any,
        meta_text: str,
        chunks: Any,
        samples: int,
        progress: bool,
        workers: int,
        dev: torch.device,
    ) -> None:
        """Compute the curves of ``chunks`` ((category, gamma, h) each, sorted and
        anchored) on ``workers`` threads and write everything to ``fh`` in order; memory
        stays bounded."""
        from tqdm import tqdm

        # the CPU's curves go in cache-sized pieces over several threads; a GPU takes a
        # chunk whole, from one thread
        curve_chunk = _CURVE_CHUNK if dev.type == "cpu" else None
        self.writer = NpzStreamWriter(fh, self.specs)
        self.writer.write("meta", np.array(meta_text, dtype=self.specs["meta"][1]))
        bar = tqdm(
            total=samples, unit="sample", unit_scale=True, desc="generate", delay=2.0,
            disable=not progress,
        )  # fmt: skip
        in_flight: deque[tuple[np.ndarray, np.ndarray, np.ndarray, Future]] = deque()
        with bar, _curve_pool(workers) as pool:
            for cat, gamma, h in chunks:
                job = pool.submit(
                    curves_numpy, gamma, h, self.settings,
                    chunk_size=curve_chunk or len(cat), device=dev,
                )  # fmt: skip
                in_flight.append((cat, gamma, h, job))
                while len(in_flight) > workers:  # keep the workers busy, memory bounded
                    bar.update(self._emit(*in_flight.popleft()))
            while in_flight:
                bar.update(self._emit(*in_flight.popleft()))
        self.writer.close()

    def _emit(self, cat: np.ndarray, gamma: np.ndarray, h: np.ndarray, job: Future) -> int:
        """Write one chunk once its curves are done; returns its size."""
        curves = job.result()
        k = len(cat)
        check_curves(curves, self.settings, first_row=self.pos)
        split = self.labels[self.pos : self.pos + k]
        self.writer.write("gamma", gamma)
        self.writer.write("h", h)
        self.writer.write("category", self.cat_names[cat])
        self.writer.write("split", self.split_names[split])
        for name in CURVE_ARRAYS:
            self.writer.write(name, curves[name])
        if self.examples:
            curves.update(gamma=gamma, h=h)
            test = split == SPLITS.index("test")
            _keep_examples(self.kept, self.examples, cat, test, curves)
        self.pos += k
        return k


@contextlib.contextmanager
def _curve_pool(workers: int) -> Iterator[ThreadPoolExecutor]:
    """Threads that compute curves, each with one torch intra-op thread.

    Chunks run side by side instead of every torch op being split over OpenMP threads, which
    keeps all cores busy without per-op barriers (on a machine shared with other jobs, OpenMP
    threads waiting on each other made the same run several times slower). torch's thread
    setting is per thread; the caller's is restored on exit.
    """
    previous = torch.get_num_threads()
    try:
        with ThreadPoolExecutor(workers, initializer=torch.set_num_threads, initargs=(1,)) as pool:
            yield pool
    finally:
        torch.set_num_threads(previous)


def _keep_examples(
    kept: dict[int, list[dict[str, np.ndarray]]],
    wanted: int,
    cat: np.ndarray,
    eligible: np.ndarray,
    arrays: Mapping[str, np.ndarray],
) -> None:
    """Add to ``kept`` the first eligible rows of each category until it has ``wanted``."""
    for c in np.unique(cat):
        have = sum(len(r["h"]) for r in kept[int(c)])
        rows = np.flatnonzero((cat == c) & eligible)[: max(0, wanted - have)]
        if rows.size:
            kept[int(c)].append({key: value[rows] for key, value in arrays.items()})


def check_curves(curves: Mapping[str, np.ndarray], settings: CellSettings, first_row: int) -> None:
    """Refuse curves that are not finite, or whose scales are not positive (float32 underflow
    or overflow for an extreme cell): a dataset never holds a silent NaN."""
    for name in CURVE_ARRAYS:
        values = np.asarray(curves[name])
        bad = ~np.isfinite(values)
        if name in ("p_star_max", "alpha_max"):
            bad |= ~(values > 0)
        if bad.any():
            row = first_row + int(np.flatnonzero(bad.reshape(len(values), -1).any(axis=1))[0])
            raise MetainterfaceError(
                f"sample {row}: {name} is not a finite positive number in float32 for this cell "
                f"(delta_max {settings.delta_max:g}, radius {settings.radius:g}, gamma in "
                f"[{settings.gamma_min:g}, {settings.gamma_max:g}]); nothing written"
            )
