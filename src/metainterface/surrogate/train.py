"""Training the inverse surrogate through the physics layer (paper sec. 3.2, appendix A).

AdamW, cosine learning rate, the curriculum (lambda) and contact-regularisation (kappa_s)
schedules, early stopping on the validation loss. The run folder holds:

    checkpoint.pt  everything needed to resume (model, optimiser, scheduler, RNG, history),
                   written atomically after every epoch: a killed run loses at most one epoch
    model.pt       the best model so far (by validation loss), a model file for `design`
    metrics.csv    per-epoch train/validation loss, kappa, lambda, learning rate, seconds
    config.json    the settings of the run

The validation loss is the physics loss with the exact contact law (what a designer gets),
so it is comparable across epochs while kappa_s anneals.
"""

from __future__ import annotations

import hashlib
import math
import os
import time
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

import torch
from tqdm.auto import tqdm

from metainterface._device import resolve_device
from metainterface._files import strict_json
from metainterface._files.atomic import output_set, write_text
from metainterface._files.provenance import HASH_DIGITS, provenance
from metainterface.errors import MetainterfaceError
from metainterface.physics.cell import CellSettings
from metainterface.physics.curves import curve
from metainterface.surrogate.checkpoint import load_model, save_model
from metainterface.surrogate.config import TrainConfig
from metainterface.surrogate.data import Split
from metainterface.surrogate.loss import (
    PAPER_WEIGHTS,
    CurveTargets,
    LossWeights,
    law_error,
    param_loss,
    physics_loss,
)
from metainterface.surrogate.model import InverseMLP
from metainterface.surrogate.run_state import RunState, save_epoch
from metainterface.surrogate.run_state import resume as resume_run


@dataclass(frozen=True)
class TrainResult:
    """What a training run did: its folder (``run_dir / "model.pt"`` is the best model), the
    epochs run, the best epoch and its validation loss, whether early stopping ended it, and
    the wall time [s]."""

    run_dir: Path
    epochs_run: int
    best_epoch: int
    best_val_loss: float
    stopped_early: bool
    seconds: float


def evaluate_loss(
    model: InverseMLP,
    split: Split,
    settings: CellSettings,
    weights: LossWeights = PAPER_WEIGHTS,
    chunk: int = 4096,
    reads: str = "curves",
    n_delta: int | None = None,
) -> float:
    """Mean exact-physics loss of the model on a split (no gradients, eval mode), on the
    split's device (the model must be there too); ``reads`` as in :class:`TrainConfig`;
    ``n_delta`` the adhesive sweep's approaches (None: 64)."""
    model.eval()
    total = 0.0
    with torch.no_grad():
        for lo in range(0, len(split), chunk):
            idx = torch.arange(lo, min(lo + chunk, len(split)), device=split.features.device)
            feats, targets, _, _ = split.rows(idx)
            gamma, h = model.design(feats, settings)
            loss = batch_loss(
                gamma,
                h,
                targets,
                settings,
                weights,
                reads,
                n_delta=n_delta,
                adhesion=split.adhesion_rows(idx),
            )
            total += float(loss) * len(idx)
    return total / len(split)


def batch_loss(
    gamma: torch.Tensor,
    h: torch.Tensor,
    targets: CurveTargets,
    settings: CellSettings,
    weights: LossWeights,
    reads: str = "curves",
    smooth: float | None = None,
    n_delta: int | None = None,
    adhesion: torch.Tensor | None = None,
    window: float = 0.0,
) -> torch.Tensor:
    """The training loss of predicted (B, N) designs (a scalar). Curves: the composite loss
    on the design's curve (``smooth``: the softplus steepness kappa_s, None for the exact
    law; ``n_delta`` Delta samples). Laws: ``weights.curve`` times the mean
    :func:`~metainterface.surrogate.loss.law_error`, exact law at the target's pressures
    (a target that ends early is seen at full resolution). Adhesive: ``weights.curve``
    times the mean :func:`~metainterface.surrogate.adhesive.adhesive_error` at each
    target's work of adhesion ``adhesion`` (B,), on an ``n_delta`` sweep, read over a load
    ``window`` (a fraction of P*_max; 0 the plain read)."""
    if reads == "adhesive":
        from metainterface.surrogate.adhesive import adhesive_error

        if adhesion is None:
            raise MetainterfaceError("adhesive targets need their work of adhesion")
        err = adhesive_error(
            gamma, h, targets, settings, adhesion, n_delta=n_delta or 64, window=window
        )
        return weights.curve * err.mean()
    if reads == "laws":
        return weights.curve * law_error(gamma, h, targets, settings).mean()
    pred = curve(gamma, h, settings, smooth=smooth, n_delta=n_delta)
    return physics_loss(pred, targets, weights)


def _check_sizes(train: Split, val: Split, batch_size: int) -> None:
    if len(train) < 2 or len(val) < 1:
        raise MetainterfaceError(
            f"dataset too small: {len(train)} training and {len(val)} validation samples"
        )
    if batch_size > len(train):
        raise MetainterfaceError(
            f"batch size {batch_size} is larger than the training split ({len(train)} samples)"
        )


def train(
    train_split: Split,
    val_split: Split,
    settings: CellSettings,
    out_dir: str | os.PathLike[str],
    config: TrainConfig | None = None,
    *,
    resume: bool = False,
    progress: bool = True,
    dataset_info: dict[str, Any] | None = None,
    device: str | torch.device = "cpu",
) -> TrainResult:
    """Train (or resume) a surrogate in ``out_dir``; returns a summary of the run.

    ``device`` ("auto", "cpu", "cuda", "cuda:N"): where the model, both splits and every
    step live. The model file and checkpoint hold CPU tensors whatever the device, so a
    run can be resumed, and its model used, on another one."""
    config = config or TrainConfig()
    _check_sizes(train_split, val_split, config.batch_size)
    dev = resolve_device(device)
    # the whole dataset on the device once: batches are then gathers there, no copies
    train_split, val_split = train_split.to(dev), val_split.to(dev)
    out = Path(out_dir)
    model, opt, sched = _model_and_optimiser(settings, config, train_split, resume, dev)
    state = RunState()
    if resume:
        state = resume_run(out / "checkpoint.pt", config, dataset_info, model, opt, sched, dev)
    elif (out / "checkpoint.pt").exists():
        raise MetainterfaceError(f"{out} already holds a run; use --resume or another --out")
    run_info = {
        "settings": settings.to_dict(),
        "model": model.architecture(),
        "train": asdict(config),
        "dataset": dataset_info or {},
        **({"init_sha256": _file_hash(config.init)} if config.init else {}),
        "provenance": provenance(),
    }
    write_text(out / "config.json", strict_json.dumps(run_info, indent=2, default=str) + "\n")
    t_run = time.perf_counter()
    stopped = False
    bar = tqdm(
        range(state.epoch, config.epochs),
        initial=state.epoch,
        total=config.epochs,
        unit="epoch",
        disable=not progress,
        desc="train",
    )
    for epoch in bar:
        t0 = time.perf_counter()
        kappa, lam = config.schedules.kappa(epoch), config.schedules.lam(epoch)
        run_loss, batches = _train_epoch(model, opt, train_split, settings, config, epoch, dev)
        lr = opt.param_groups[0]["lr"]
        sched.step()
        val = _validation_loss(model, val_split, settings, config, epoch)
        row = {"epoch": epoch + 1, "train_loss": run_loss / batches, "val_loss": val}
        row.update(kappa=kappa, **{"lambda": lam}, lr=lr, seconds=time.perf_counter() - t0)
        state.history.append(row)
        if not math.isfinite(run_loss):
            raise MetainterfaceError(
                f"training diverged at epoch {epoch + 1} (training loss {run_loss}); lower --lr"
            )
        state.epoch = epoch + 1
        with output_set():  # an epoch's files go out together: a kill loses one epoch at most
            if val < state.best:
                state.best, state.best_epoch, state.bad = val, epoch + 1, 0
                save_model(
                    out / "model.pt", model, {**run_info, "epoch": epoch + 1, "val_loss": val}
                )
            else:
                state.bad += 1
            save_epoch(out, state, config, dataset_info, model, opt, sched, dev)
        bar.set_postfix(train=f"{run_loss / batches:.4f}", val=f"{val:.4f}", kappa=f"{kappa:.0f}")
        if state.bad >= config.patience:
            stopped = True
            break
    bar.close()
    return TrainResult(
        out, len(state.history), state.best_epoch, state.best, stopped,
        time.perf_counter() - t_run,
    )  # fmt: skip


def _model_and_optimiser(
    settings: CellSettings,
    config: TrainConfig,
    train_split: Split,
    resume: bool,
    dev: torch.device,
) -> tuple[InverseMLP, torch.optim.Optimizer, Any]:
    """The network (seeded; from ``config.init``'s weights where given and not resuming,
    its inputs standardised on ``train_split``), AdamW and the cosine schedule."""
    torch.manual_seed(config.seed)
    model = InverseMLP(
        settings.n_asperities,
        settings.n_steps,
        config.max_gap,
        adhesion_input=config.adhesion_input,
    ).to(dev)
    if config.init is not None and not resume:
        _start_from(model, config.init, settings, train_split.features)
    else:
        model.set_input_scaling(train_split.features)
    # fused: one kernel for all parameters, half the optimiser time of the foreach default
    opt = torch.optim.AdamW(
        model.parameters(), lr=config.lr, weight_decay=config.weight_decay, fused=True
    )
    return model, opt, torch.optim.lr_scheduler.CosineAnnealingLR(opt, T_max=config.epochs)


def _validation_loss(
    model: InverseMLP, val_split: Split, settings: CellSettings, config: TrainConfig, epoch: int
) -> float:
    """The epoch's validation loss (the exact contact law); a diverged one is an error."""
    val = evaluate_loss(
        model,
        val_split,
        settings,
        config.weights,
        reads=config.reads,
        n_delta=config.physics_steps if config.reads == "adhesive" else None,
    )
    if not math.isfinite(val):
        raise MetainterfaceError(f"training diverged at epoch {epoch + 1} (validation loss {val})")
    return val


def _train_epoch(
    model: InverseMLP,
    opt: torch.optim.Optimizer,
    train_split: Split,
    settings: CellSettings,
    config: TrainConfig,
    epoch: int,
    dev: torch.device,
) -> tuple[float, int]:
    """One epoch of AdamW steps over the shuffled training split, the epoch's kappa_s,
    lambda and snap window: (summed batch loss, batches)."""
    schedules = config.schedules
    kappa, lam = schedules.kappa(epoch), schedules.lam(epoch)
    n = len(train_split)
    model.train()
    # drawn on the CPU whatever the device: the same seed, the same batches everywhere
    order = torch.randperm(
        n, generator=torch.Generator().manual_seed(config.seed * 100_003 + epoch)
    ).to(dev)
    # summed on the device and read once an epoch (a float() per batch would wait for
    # each step to finish); float64, so the sum equals the per-batch Python sum on CPU
    epoch_loss = torch.zeros((), dtype=torch.float64, device=dev)
    batches = 0
    for lo in range(0, n - config.batch_size + 1, config.batch_size):
        feats, targets, g_t, h_t = train_split.rows(order[lo : lo + config.batch_size])
        gamma, h = model.design(feats, settings)
        loss = batch_loss(
            gamma,
            h,
            targets,
            settings,
            config.weights,
            config.reads,
            kappa,
            config.physics_steps,
            adhesion=train_split.adhesion_rows(order[lo : lo + config.batch_size]),
            window=schedules.window(epoch),
        )
        if lam > 0:
            loss = loss + lam * param_loss(gamma, h, g_t, h_t, settings)
        opt.zero_grad(set_to_none=True)
        loss.backward()
        opt.step()
        epoch_loss += loss.detach()
        batches += 1
    return float(epoch_loss), batches


def _file_hash(path: str) -> str | None:
    """'sha256:<hex>' of a file's bytes: names the model a run started from, wherever it is
    (None if it is gone, as it may be when a run is resumed)."""
    if not Path(path).is_file():
        return None
    digest = hashlib.sha256(Path(path).read_bytes()).hexdigest()
    return "sha256:" + digest[:HASH_DIGITS]


def _start_from(model: InverseMLP, path: str, settings: CellSettings, features) -> None:
    """Load a model file's weights into ``model`` and refit the input standardisation to
    ``features``, folding the change into the first layer so the network computes what the
    file's did. Inputs that were constant where the file was trained
    (``InverseMLP.constant_inputs``) carried nothing; their weights start at 0, as do those
    of an input the file's network did not have (the adhesion column)."""
    src, trained, _ = load_model(path)
    if trained != settings:
        raise MetainterfaceError(
            f"init model {path}: trained for another cell than the dataset's; give --init "
            "(TrainConfig.init) a model trained on this dataset's cell"
        )
    if src.max_gap != model.max_gap:
        raise MetainterfaceError(
            f"init model {path}: max_gap {src.max_gap} differs from this run's {model.max_gap}"
        )
    state = src.state_dict()
    extra = model.in_mean.numel() - src.in_mean.numel()
    if extra < 0 or (extra > 0 and not model.adhesion_input):
        raise MetainterfaceError(
            f"init model {path}: reads {src.in_mean.numel()} inputs, this run's network "
            f"{model.in_mean.numel()}"
        )
    if extra:  # the new input column starts with no weight, standardised as a no-op
        first = state["net.0.weight"]
        state["net.0.weight"] = torch.cat([first, first.new_zeros(first.shape[0], extra)], 1)
        state["in_mean"] = torch.cat([state["in_mean"], state["in_mean"].new_zeros(extra)])
        state["in_std"] = torch.cat([state["in_std"], state["in_std"].new_ones(extra)])
    with torch.no_grad():
        model.load_state_dict(state)
        old_mean, old_std = model.in_mean.clone(), model.in_std.clone()
        live = ~model.constant_inputs()
        model.set_input_scaling(features)
        scale = torch.where(live, model.in_std / old_std, 0.0)
        shift = torch.where(live, (model.in_mean - old_mean) / old_std, 0.0)
        first = model.net[0]
        first.bias += first.weight @ shift
        first.weight *= scale[None]
