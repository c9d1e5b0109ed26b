"""The synthetic training dataset (paper sec. 2.4): generate it into one .npz
(read back by ``metainterface.data.load``).

A dataset of S samples of an N-asperity cell holds, per sample, the design sorted by height
(gamma moving with its h) and anchored so min h = 0, and its exact alpha(P*) curve in the
normalised form of appendix A.1. Arrays of the file:

    gamma (S, N) float64, h (S, N) float64 [units of R], category (S,) str, split (S,) str
    in {train, val, test}, p_star_max (S,) float32 and alpha_max (S,) float32 (P* and alpha at
    Delta = Delta_max), alpha_hat (S, n_steps) float32 and stiffness_hat (S, n_steps) float32
    on the uniform grid P / P*_max in [0, 1], and meta: JSON text (format, every setting, seed,
    package version; see ``generate_dataset``).

Reproducibility: category c's samples come in blocks of at most ``block`` rows; block b is
drawn by a generator seeded with ``SeedSequence(seed, spawn_key=(c, b))`` (the split with
spawn key (6,)). The blocks depend only on (samples, block), not on the processing chunk, so
a seed gives the same arrays whatever ``chunk`` and ``workers`` are. Memory stays flat in S: each
chunk is sampled, computed and written straight to its place in the file (``NpzStreamWriter``).
"""

from __future__ import annotations

import json
import os
import time
from collections.abc import Iterator, Mapping, Sequence
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import torch

from metainterface._device import resolve_device
from metainterface._files.atomic import atomic_open, ensure_parent
from metainterface._files.provenance import provenance
from metainterface.data._stream import Stream
from metainterface.data.categories import CATEGORIES, CATEGORY_NAMES
from metainterface.data.categories import category as find_category
from metainterface.data.load import FORMAT, SPLIT_FRACTIONS, SPLITS
from metainterface.errors import MetainterfaceError
from metainterface.physics.cell import CellSettings

DEFAULT_CHUNK = 4096  # samples sampled, computed and written together
DEFAULT_BLOCK = 32768  # largest block one generator draws (fixes the LHS partition)


def allocate(total: int, fractions: Sequence[float]) -> np.ndarray:
    """Integer counts that sum to ``total``, proportional to ``fractions`` (largest remainder).

    Ties in the remainders go to the earlier entry. Returns an int64 array like ``fractions``.
    """
    w = np.asarray(fractions, dtype=np.float64)
    raw = np.round(total * w / w.sum(), 9)
    counts = np.floor(raw).astype(np.int64)
    order = np.argsort(-(raw - counts), kind="stable")
    counts[order[: total - int(counts.sum())]] += 1
    return counts


def sort_and_anchor(gamma: np.ndarray, h: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Sort each (S, N) design by height, gamma moving with its h, and shift so min h = 0."""
    order = np.argsort(h, axis=1, kind="stable")
    h = np.take_along_axis(h, order, axis=1)
    gamma = np.take_along_axis(gamma, order, axis=1)
    return gamma, h - h[:, :1]


@dataclass(frozen=True)
class GenerationReport:
    """What ``generate_dataset`` wrote.

    counts: samples per category; split_counts: samples per split; seconds: wall time;
    examples: per category, up to a few test-split rows (gamma, h, p_star_max, alpha_max,
    alpha_hat, stiffness_hat) for figures.
    """

    path: Path
    samples: int
    seed: int
    settings: CellSettings
    counts: dict[str, int]
    split_counts: dict[str, int]
    seconds: float
    examples: dict[str, dict[str, np.ndarray]] = field(repr=False)


def _whole(name: str, value: Any, low: int) -> int:
    if isinstance(value, bool) or not isinstance(value, int | np.integer) or value < low:
        raise MetainterfaceError(f"{name} must be a whole number >= {low}, got {value!r}")
    return int(value)


def _category_params(params: Mapping[str, Any] | None) -> list[Any]:
    params = dict(params or {})
    for name in params:
        find_category(name)  # unknown names raise
    out = []
    for c in CATEGORIES:
        p = params.get(c.name, c.params)
        if type(p) is not type(c.params):
            raise MetainterfaceError(
                f"params for category {c.name!r} must be a {type(c.params).__name__}, "
                f"got {type(p).__name__}"
            )
        out.append(p)
    return out


def _plan(counts: np.ndarray, block: int) -> list[tuple[int, int, int]]:
    """(category index, block index, rows) of every block, in file order."""
    plan = []
    for c, n in enumerate(int(x) for x in counts):
        n_blocks = -(-n // block)
        for b, rows in enumerate(allocate(n, [1.0] * n_blocks) if n_blocks else []):
            plan.append((c, b, int(rows)))
    return plan


def split_counts(counts: Sequence[int]) -> np.ndarray:
    """(categories, 3) train/val/test counts: 80/10/10 overall and within every category.

    Overall: val = round(S / 10) (halves up), test = floor(S / 10), train the rest. Each
    category gets the val and test samples whose running index (categories in file order)
    falls in it, so its own shares are within one sample of 10 % and never negative.
    """
    ends = np.cumsum(np.asarray(counts, dtype=np.int64))
    starts = ends - np.asarray(counts, dtype=np.int64)

    def val(t: np.ndarray) -> np.ndarray:
        return (t + 5) // 10

    def test(t: np.ndarray) -> np.ndarray:
        return t // 10

    n_val, n_test = val(ends) - val(starts), test(ends) - test(starts)
    return np.stack([ends - starts - n_val - n_test, n_val, n_test], axis=1)


def _split_labels(counts: np.ndarray, seed: int) -> np.ndarray:
    """(S,) uint8 split index per sample (see ``split_counts``), shuffled in each category."""
    rng = np.random.default_rng(np.random.SeedSequence(seed, spawn_key=(len(CATEGORIES),)))
    parts = [
        rng.permutation(np.repeat(np.arange(len(SPLITS), dtype=np.uint8), per_split))
        for per_split in split_counts(counts)
    ]
    return np.concatenate(parts) if parts else np.empty(0, np.uint8)


def _designs(
    plan: list[tuple[int, int, int]], seed: int, settings: CellSettings, params: list[Any]
) -> Iterator[tuple[np.ndarray, np.ndarray, np.ndarray]]:
    """(category index (k,), gamma (k, N), h (k, N)) block by block, in file order."""
    n = settings.n_asperities
    for c, b, rows in plan:
        rng = np.random.default_rng(np.random.SeedSequence(seed, spawn_key=(c, b)))
        gamma, h = CATEGORIES[c].sampler(rng, rows, settings, params[c])
        if gamma.shape != (rows, n) or h.shape != (rows, n):  # pragma: no cover - sampler bug
            raise RuntimeError(f"sampler {CATEGORIES[c].name} returned a wrong shape")
        yield np.full(rows, c, dtype=np.uint8), gamma, h


def _rechunk(
    blocks: Iterator[tuple[np.ndarray, ...]], chunk: int
) -> Iterator[tuple[np.ndarray, ...]]:
    """Regroup a stream of row blocks into chunks of exactly ``chunk`` rows (the last: fewer)."""
    pending: list[tuple[np.ndarray, ...]] = []
    have = 0

    def take(k: int) -> tuple[np.ndarray, ...]:
        nonlocal have
        parts = []
        while k:
            first = pending[0]
            if len(first[0]) <= k:
                parts.append(pending.pop(0))
                k -= len(first[0])
            else:
                parts.append(tuple(a[:k] for a in first))
                pending[0] = tuple(a[k:] for a in first)
                k = 0
        have -= sum(len(p[0]) for p in parts)
        if len(parts) == 1:
            return parts[0]
        return tuple(np.concatenate(arrays) for arrays in zip(*parts, strict=True))

    for blk in blocks:
        pending.append(blk)
        have += len(blk[0])
        while have >= chunk:
            yield take(chunk)
    if have:
        yield take(have)


def generate_dataset(
    samples: int,
    seed: int,
    settings: CellSettings,
    out: str | os.PathLike[str],
    progress: bool = True,
    chunk: int = DEFAULT_CHUNK,
    *,
    block: int = DEFAULT_BLOCK,
    params: Mapping[str, Any] | None = None,
    examples: int = 3,
    workers: int | None = None,
    device: str | torch.device = "cpu",
) -> GenerationReport:
    """Generate ``samples`` designs of the six categories with their exact curves into ``out``.

    samples: S > 0, split over the categories 20/16/16/16/16/16 % (largest remainder).
    seed: integer >= 0; the same (samples, seed, settings, block, params) give the same arrays.
    settings: the cell (N, R, E*, Delta_max, gamma bounds, n_steps of the curves).
    out: the .npz path, written atomically (nothing under that name unless complete).
    progress: show a tqdm bar (on stderr) once a run has taken more than 2 s.
    chunk: samples processed together (about 1.2 kB each, on top of the fixed working memory
        of ``curves_numpy``); results do not depend on it.
    block: largest block of one category drawn by one generator (results depend on it;
        recorded in meta). Each LHS block is one Latin hypercube.
    params: category name -> parameter object (e.g. ``{"truncated": TruncatedParams(...)}``)
        replacing that category's defaults.
    examples: test-split rows per category kept in the report for figures.
    workers: threads computing curves side by side, each with one torch thread; default
        min(4, torch.get_num_threads()). Results do not depend on it.
    device: where the curves are computed ("auto", "cpu", "cuda", "cuda:N"). On a GPU each
        chunk goes in one piece, from one worker thread (the next chunk is sampled on the
        CPU meanwhile); float reductions there round differently from the CPU's, so a seed
        gives the same arrays on one device, equal to float32 rounding across devices.
    Curves use the exact Macaulay bracket, computed in float32 by ``curves_numpy``.
    """
    if not isinstance(settings, CellSettings):
        raise MetainterfaceError(f"settings must be a CellSettings, got {type(settings).__name__}")
    samples = _whole("samples", samples, 1)
    seed = _whole("seed", seed, 0)
    chunk = _whole("chunk", chunk, 1)
    block = _whole("block", block, 1)
    examples = _whole("examples", examples, 0)
    workers = min(4, torch.get_num_threads()) if workers is None else workers
    workers = _whole("workers", workers, 1)
    dev = resolve_device(device)
    if dev.type != "cpu":  # a GPU takes a chunk whole, from one thread
        workers = 1
    cat_params = _category_params(params)
    started = time.perf_counter()

    counts = allocate(samples, [c.fraction for c in CATEGORIES])
    labels = _split_labels(counts, seed)
    per_split = np.bincount(labels, minlength=len(SPLITS))
    meta_text = _meta_text(samples, seed, settings, block, counts, per_split, cat_params)
    specs = _array_specs(samples, settings, meta_text)
    path = Path(out)
    try:
        ensure_parent(path)  # fail before any work on a path that cannot be written
    except MetainterfaceError as exc:
        raise MetainterfaceError(f"cannot write {path}: {exc}") from None
    blocks = _designs(_plan(counts, block), seed, settings, cat_params)
    stream = Stream(settings, labels, specs, examples)
    try:
        with atomic_open(path, "wb") as fh:
            chunks = ((c, *sort_and_anchor(g, h)) for c, g, h in _rechunk(blocks, chunk))
            stream.write(fh, meta_text, chunks, samples, progress, workers, dev)
    except OSError as exc:
        raise MetainterfaceError(f"cannot write {path}: {exc.strerror or exc}") from None
    kept = stream.kept
    example_arrays = {
        CATEGORIES[c].name: {key: np.concatenate([r[key] for r in rows]) for key in rows[0]}
        for c, rows in kept.items()
        if rows
    }
    return GenerationReport(
        path=path,
        samples=samples,
        seed=seed,
        settings=settings,
        counts={c.name: int(x) for c, x in zip(CATEGORIES, counts, strict=True)},
        split_counts={s: int(x) for s, x in zip(SPLITS, per_split, strict=True)},
        seconds=time.perf_counter() - started,
        examples=example_arrays,
    )


def _meta_text(
    samples: int,
    seed: int,
    settings: CellSettings,
    block: int,
    counts: np.ndarray,
    per_split: np.ndarray,
    cat_params: list[Any],
) -> str:
    """The file's "meta" entry (JSON): format, seed, cell, block, categories, splits and the
    provenance of the run."""
    meta = provenance(
        format=FORMAT,
        samples=samples,
        seed=seed,
        cell=settings.to_dict(),
        block=block,
        curves={"bracket": "exact", "dtype": "float32", "n_steps": settings.n_steps},
        categories={
            c.name: {"fraction": c.fraction, "count": int(n), "params": asdict(p)}
            for c, n, p in zip(CATEGORIES, counts, cat_params, strict=True)
        },
        splits={
            "fractions": dict(zip(SPLITS, SPLIT_FRACTIONS, strict=True)),
            "counts": {s: int(n) for s, n in zip(SPLITS, per_split, strict=True)},
            "stratified_by": "category",
        },
    )
    return json.dumps(meta, sort_keys=True)


def _array_specs(
    samples: int, settings: CellSettings, meta_text: str
) -> dict[str, tuple[tuple[int, ...], Any]]:
    """name -> (shape, dtype) of every array the .npz holds, for the streaming writer."""
    n, steps = settings.n_asperities, settings.n_steps
    return {
        "gamma": ((samples, n), np.float64),
        "h": ((samples, n), np.float64),
        "category": ((samples,), f"<U{max(len(s) for s in CATEGORY_NAMES)}"),
        "split": ((samples,), f"<U{max(len(s) for s in SPLITS)}"),
        "p_star_max": ((samples,), np.float32),
        "alpha_max": ((samples,), np.float32),
        "alpha_hat": ((samples, steps), np.float32),
        "stiffness_hat": ((samples, steps), np.float32),
        "meta": ((), f"<U{len(meta_text)}"),
    }
