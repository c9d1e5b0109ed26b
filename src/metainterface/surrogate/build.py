"""Your own design space: a dataset for a cell, a surrogate trained on it, its evaluation."""

from __future__ import annotations

import hashlib
import json
import os
from pathlib import Path
from typing import Any

import torch

from metainterface import _checks
from metainterface._device import resolve_device
from metainterface._files import check_output_file, check_output_folder
from metainterface._threads import uses_threads
from metainterface.data import generate_dataset as _generate
from metainterface.data import load_dataset
from metainterface.data.dataset import DEFAULT_CHUNK, GenerationReport
from metainterface.physics.cell import CellSettings
from metainterface.surrogate.checkpoint import default_model_path, load_model
from metainterface.surrogate.config import TrainConfig
from metainterface.surrogate.data import split_of
from metainterface.surrogate.evaluate import evaluate
from metainterface.surrogate.laws import law_split
from metainterface.surrogate.loss import weights_of
from metainterface.surrogate.train import TrainResult, train

#: Seeds of the friction-law-like targets a laws network is evaluated on (train, test):
#: fixed, and apart from training's (its seed and seed + 1).
LAW_SEEDS = (1001, 1002)

#: Largest dataset one call makes (~1.2 kB a sample on disk and in memory).
MAX_SAMPLES = 10_000_000


@uses_threads("heavy")
def generate_dataset(
    samples: int,
    out: str | os.PathLike[str],
    *,
    seed: int = 0,
    settings: CellSettings | None = None,
    progress: bool = True,
    chunk: int = DEFAULT_CHUNK,
    device: str = "auto",
) -> GenerationReport:
    """Generate a training dataset: ``samples`` designs of the paper's six topography
    categories with their exact normalised curves, split 80/10/10, written atomically to
    ``out`` (.npz). The same (samples, seed, settings) give the same arrays; ``chunk``
    (samples computed together) changes memory, not results. ``device`` ("auto", "cpu",
    "cuda", "cuda:N") computes the curves there ("auto": CUDA when torch sees it); the same
    seed gives the same arrays on one device (docs: concepts/devices)."""
    samples = _checks.whole("samples", samples, low=1, high=MAX_SAMPLES)
    seed = _checks.seed(seed)
    dev = resolve_device(device)
    chunk = _checks.whole("chunk", chunk, low=1, high=1_000_000)
    settings = settings or CellSettings()
    out = check_output_file(out)
    row = 8 * 2 * settings.n_asperities + 4 * (2 * settings.n_steps + 2) + 16
    _checks.disk_room("samples", samples, samples * row, out.parent)
    # a chunk's curves, in flight on a few threads, with the sweep's working arrays
    _checks.affordable("chunk", chunk, 8 * chunk * row)
    return _generate(samples, seed, settings, out, progress=progress, chunk=chunk, device=dev)


@uses_threads("heavy")
def train_surrogate(
    dataset: str | os.PathLike[str],
    out: str | os.PathLike[str],
    config: TrainConfig | None = None,
    *,
    resume: bool = False,
    progress: bool = True,
    device: str = "auto",
) -> TrainResult:
    """Train the inverse network on a dataset (``generate_dataset``) into the run folder
    ``out``: one atomic checkpoint per epoch (``resume=True`` continues), the best model as
    ``out/model.pt``, usable as ``design(..., effort=Effort(surrogate=out / "model.pt"))``. With
    ``config.reads == "laws"`` it trains on targets made from the dataset's cells the way
    friction laws arrive (``metainterface.surrogate.laws``), usually from ``config.init``,
    the shipped network (``TrainConfig.laws()``); with ``"adhesive"`` on the adhesive loading
    curves of its cells (``metainterface.surrogate.adhesive``, ``TrainConfig.adhesive()``).
    ``device``
    ("auto", "cpu", "cuda", "cuda:N") is where the model and the dataset live while it
    trains; the files load on any device (a run may be resumed on another one)."""
    dev = resolve_device(device)
    check_output_folder(out)
    ds = load_dataset(dataset)
    fingerprint = hashlib.sha256(json.dumps(ds.meta, sort_keys=True).encode()).hexdigest()[:16]
    config = config or TrainConfig()
    train_split, val_split = split_of(ds, "train"), split_of(ds, "val")
    if config.reads == "laws":
        with torch.inference_mode():
            # the validation targets get their own seed: other cuts of other cells
            train_split = law_split(train_split, ds.settings, config.seed, progress=progress)
            val_split = law_split(val_split, ds.settings, config.seed + 1, progress=progress)
    elif config.reads == "adhesive":
        from metainterface.surrogate.adhesive import adhesive_split

        with torch.inference_mode():
            train_split, val_split = (
                adhesive_split(
                    part,
                    ds.settings,
                    config.seed + k,
                    adhesion_input=config.adhesion_input,
                    progress=progress,
                    device=dev,
                )
                for k, part in enumerate((train_split, val_split))
            )
    return train(
        train_split,
        val_split,
        ds.settings,
        out,
        config,
        resume=resume,
        progress=progress,
        device=dev,
        dataset_info={
            "path": str(dataset),
            "samples": len(ds),
            "seed": ds.seed,
            "fingerprint": fingerprint,
        },
    )


@uses_threads("heavy")
def evaluate_surrogate(
    dataset: str | os.PathLike[str],
    surrogate: str | os.PathLike[str] | None = None,
    *,
    progress: bool = True,
) -> dict[str, Any]:
    """Zero-shot errors of a surrogate on a dataset's test split, per category and overall
    (median and 90th-percentile relative curve error, log10 errors of P*_max and alpha_max)
    and the train/test loss gap. A friction-law network (``TrainConfig.laws``) is evaluated
    on friction-law-like targets made from the split's cells, per kind (``progress``: a
    bar while they are made)."""
    path = Path(surrogate) if surrogate is not None else default_model_path()
    model, settings, config = load_model(path)
    ds = load_dataset(dataset, settings)
    train_split, test_split = split_of(ds, "train"), split_of(ds, "test")
    reads = config.get("train", {}).get("reads", "curves")
    if reads == "laws":  # its own kind of targets, made from the test cells (fixed seeds)
        with torch.inference_mode():
            train_split = law_split(train_split, settings, LAW_SEEDS[0], progress=progress)
            test_split = law_split(test_split, settings, LAW_SEEDS[1], progress=progress)
    elif reads == "adhesive":
        from metainterface.surrogate.adhesive import adhesive_split

        reads_w = bool(config.get("model", {}).get("adhesion_input", False))
        with torch.inference_mode():
            train_split, test_split = (
                adhesive_split(part, settings, seed, adhesion_input=reads_w, progress=progress)
                for part, seed in zip((train_split, test_split), LAW_SEEDS, strict=True)
            )
    return evaluate(model, train_split, test_split, settings, weights_of(config), reads)
