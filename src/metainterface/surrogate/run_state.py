"""A training run's state on disk: the checkpoint and metrics.csv written with each epoch
(together: a killed run loses at most the epoch in progress), and the checkpoint read back
to resume, refused where it was made with other settings or on another dataset."""

from __future__ import annotations

import os
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import torch

from metainterface._files.columns import write_columns
from metainterface.errors import MetainterfaceError
from metainterface.surrogate.checkpoint import load_torch, save_torch
from metainterface.surrogate.config import TrainConfig
from metainterface.surrogate.model import InverseMLP

#: The columns of metrics.csv, one row an epoch.
METRICS = ("epoch", "train_loss", "val_loss", "kappa", "lambda", "lr", "seconds")


@dataclass
class RunState:
    """Where a run stands: epochs done, the best validation loss and its epoch, epochs
    since it, and the per-epoch history (rows of ``METRICS``)."""

    epoch: int = 0
    best: float = float("inf")
    best_epoch: int = -1
    bad: int = 0
    history: list[dict[str, float]] = field(default_factory=list)


def save_epoch(
    out: Path,
    state: RunState,
    config: TrainConfig,
    dataset_info: dict[str, Any] | None,
    model: InverseMLP,
    opt: torch.optim.Optimizer,
    sched: Any,
    dev: torch.device,
) -> None:
    """Write the run's checkpoint.pt (model, optimiser, scheduler, RNGs, ``state``) and
    metrics.csv after an epoch."""
    save_torch(
        out / "checkpoint.pt",
        {
            "config": asdict(config),
            "dataset": dataset_info or {},
            "model": model.state_dict(),
            "optimizer": opt.state_dict(),
            "scheduler": sched.state_dict(),
            "rng": torch.get_rng_state(),
            **({"cuda_rng": torch.cuda.get_rng_state(dev)} if dev.type == "cuda" else {}),
            "epoch": state.epoch,
            "best": state.best,
            "best_epoch": state.best_epoch,
            "bad": state.bad,
            "history": state.history,
        },
    )
    write_metrics(out / "metrics.csv", state.history)


def resume(
    ckpt_path: Path,
    config: TrainConfig,
    dataset_info: dict[str, Any] | None,
    model: InverseMLP,
    opt: torch.optim.Optimizer,
    sched: Any,
    dev: torch.device,
) -> RunState:
    """Load a run's checkpoint into model, optimiser, scheduler and the RNGs; returns where
    the run stood. A checkpoint made with other settings or on another dataset is refused,
    naming what differs."""
    if not ckpt_path.is_file():
        raise MetainterfaceError(f"--resume: no checkpoint in {ckpt_path.parent}")
    state = load_torch(ckpt_path, "checkpoint")
    if state["config"] != asdict(config):
        changed = sorted(k for k, v in asdict(config).items() if state["config"].get(k, v) != v)
        was = ", ".join(f"{k} {state['config'].get(k)!r}" for k in changed)
        raise MetainterfaceError(
            f"--resume: {ckpt_path} was made with other settings ({was}); give the "
            "same options or another --out"
        )
    _same_dataset(ckpt_path, state.get("dataset"), dataset_info)
    model.load_state_dict(state["model"])
    opt.load_state_dict(state["optimizer"])
    sched.load_state_dict(state["scheduler"])
    torch.set_rng_state(state["rng"])
    if dev.type == "cuda" and "cuda_rng" in state:  # dropout draws there on CUDA
        torch.cuda.set_rng_state(state["cuda_rng"], dev)
    # a kill between the epoch's two renames leaves metrics.csv an epoch behind: the
    # checkpoint's history is the record
    write_metrics(ckpt_path.parent / "metrics.csv", state["history"])
    return RunState(
        state["epoch"], state["best"], state["best_epoch"], state["bad"], state["history"]
    )


def _same_dataset(ckpt_path: Path, stored: dict | None, given: dict | None) -> None:
    """--resume must continue on the dataset the run started with."""
    if not stored or not given:
        return
    keys = ("fingerprint", "samples", "seed")
    if any(k in stored and k in given and stored[k] != given[k] for k in keys):
        raise MetainterfaceError(
            f"--resume: {ckpt_path} was trained on another dataset ({stored.get('path')}, "
            f"{stored.get('samples')} samples, seed {stored.get('seed')}); give that --dataset "
            "or another --out"
        )


def write_metrics(path: Path, history: list[dict[str, float]]) -> None:
    """metrics.csv of a run folder, one row an epoch (columns ``METRICS``)."""
    cols = {k: np.array([row[k] for row in history], dtype=np.float64) for k in METRICS}
    write_columns(path, cols, what="training metrics")


def read_metrics(run_dir: str | os.PathLike[str]) -> dict[str, np.ndarray]:
    """metrics.csv of a run folder as columns."""
    from metainterface._files.columns import read_columns

    return read_columns(Path(run_dir) / "metrics.csv", METRICS)
